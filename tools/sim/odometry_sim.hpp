// SPDX-License-Identifier: MIT
// Spot's encoder odometry as the payload CAN bridge would send it (spot_odometry.dbc): 50 Hz
// samples of the true 6-DOF body motion since the previous sample, in the previous body frame
// (dx, dy, dz, droll, dpitch, dyaw: the gait's bob and rocking included), with a per-robot
// scale error (1-2 %), a yaw drift proportional to distance (about 1 degree per 10 m), white
// noise, encoder slip events (feet slipping: for 0.3-2 s the translation is misreported by a
// factor and/or the heading by up to ~2 degrees; not flagged in the status byte; off unless
// asked for) and
// occasionally a sample lost on the bus. Written as a `candump -l` log stamped by the robot's
// clock.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "clocks.hpp"
#include "trajectory.hpp"

namespace msgraphs::sim {

/// Encoder slip: events at a per-robot rate along the walked distance (exponential gaps). Off by
/// default (the shipped missions the demo and the tests run), on in benchmark missions.
struct SlipConfig {
  bool enabled = false;
  double per_100m_min = 1.0, per_100m_max = 4.0;  ///< the robot's rate is drawn in this range
  double duration_min_s = 0.3, duration_max_s = 2.0;
  double scale_min = 0.5, scale_max = 1.5;  ///< translation reported x factor during the event
  double yaw_max_deg = 2.0;                 ///< |heading error| accumulated over the event
  /// Kinds drawn with these weights: translation only, heading only, both.
  double weight_scale = 0.4, weight_yaw = 0.3, weight_both = 0.3;
};

struct SlipEvent {
  double start_s = 0;  ///< mission time
  double duration_s = 0;
  const char* kind = "";  ///< "scale", "yaw" or "scale+yaw"
  double scale = 1.0;     ///< reported / true translation during the event
  double yaw_rad = 0.0;   ///< heading error added over the event
  double true_m = 0.0;    ///< distance walked during the event
};

struct OdometrySimConfig {
  double rate_hz = 50.0;
  double scale_error_min = 0.01;  ///< |scale error| is drawn per robot in [min, max]
  double scale_error_max = 0.02;
  double yaw_drift_deg_per_10m = 1.0;    ///< magnitude; sign and +-30 % drawn per robot
  double noise_xy_m = 0.0005;            ///< per sample
  double noise_yaw_rad = 0.0002;         ///< per sample
  double noise_z_m = 0.0002;             ///< per sample
  double noise_roll_pitch_rad = 0.0001;  ///< per sample
  double drop_probability = 0.002;       ///< a sample whose frames never reach the bus
  SlipConfig slip;
  std::string interface = "can0";
};

struct OdometrySimStats {
  std::uint64_t samples = 0;  ///< written
  std::uint64_t dropped = 0;  ///< lost on purpose
  double scale_error = 0.0;   ///< the robot's drawn scale error (reported x = (1 + e) true x)
  double yaw_drift_rad_per_m = 0.0;
  double path_length_m = 0.0;
  double slip_per_100m = 0.0;  ///< the robot's drawn slip rate (0: slips off)
  std::vector<SlipEvent> slips;
};

bool RenderOdometry(const Trajectory& trajectory,
                    const OdometrySimConfig& config,
                    const RobotClocks& clocks,
                    std::uint64_t seed,
                    int robot,
                    const std::string& candump_path,
                    OdometrySimStats& stats,
                    std::string& error);

}  // namespace msgraphs::sim
