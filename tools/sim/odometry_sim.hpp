// SPDX-License-Identifier: MIT
// Spot's encoder odometry as the payload CAN bridge would send it (spot_odometry.dbc): 50 Hz
// samples of body motion since the previous sample, with a per-robot scale error (1-2 %), a
// yaw drift proportional to distance (about 1 degree per 10 m), white noise, and occasionally
// a sample lost on the bus. Written as a `candump -l` log stamped by the robot's clock.
#pragma once

#include <cstdint>
#include <string>

#include "clocks.hpp"
#include "trajectory.hpp"

namespace msgraphs::sim {

struct OdometrySimConfig {
  double rate_hz = 50.0;
  double scale_error_min = 0.01;   ///< |scale error| is drawn per robot in [min, max]
  double scale_error_max = 0.02;
  double yaw_drift_deg_per_10m = 1.0;  ///< magnitude; sign and +-30 % drawn per robot
  double noise_xy_m = 0.0005;      ///< per sample
  double noise_yaw_rad = 0.0002;   ///< per sample
  double drop_probability = 0.002; ///< a sample whose frames never reach the bus
  std::string interface = "can0";
};

struct OdometrySimStats {
  std::uint64_t samples = 0;   ///< written
  std::uint64_t dropped = 0;   ///< lost on purpose
  double scale_error = 0.0;    ///< the robot's drawn scale error (reported x = (1 + e) true x)
  double yaw_drift_rad_per_m = 0.0;
  double path_length_m = 0.0;
};

bool RenderOdometry(const Trajectory& trajectory, const OdometrySimConfig& config, const RobotClocks& clocks,
                    std::uint64_t seed, int robot, const std::string& candump_path, OdometrySimStats& stats,
                    std::string& error);

}  // namespace msgraphs::sim
