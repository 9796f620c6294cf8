// SPDX-License-Identifier: MIT
// Integrates encoder-odometry samples into timestamped SE(3) poses of the base frame in the
// odometry frame (the pose at the first sample is the identity).
//
// Each sample is the motion since the previous sample, in the previous sample's body frame
// (spec section 3): pose_k = pose_{k-1} * delta_k, with delta rotation Rz(yaw) Ry(pitch) Rx(roll).
//
// Lost motion is never dropped silently. A gap in the sequence (lost frames, an incomplete
// sample) or a sample flagged invalid leaves an interval whose motion is unknown: it is bridged
// at the mean velocity of the samples on both sides, over the duration the bridge's own clock
// (SampleTime) says is missing, and the pose is flagged. Gaps longer than max_bridge are not
// extrapolated: the pose is flagged as a discontinuity and counted.
//
// Timestamps: SampleTime is the bridge's clock; poses carry host time through a lower-envelope
// offset filter on (receive time - sample time), which keeps the bridge's exact spacing.
#pragma once

#include <cstdint>

#include "msgraphs/base/clock_offset_filter.hpp"
#include "msgraphs/base/expected.hpp"
#include "msgraphs/base/time.hpp"
#include "msgraphs/drivers/can_odometry/sample_assembler.hpp"

namespace msgraphs::drivers::can_odometry {

enum PoseFlag : std::uint8_t {
  kPoseBridged = 1u << 0,        ///< motion over missing samples was extrapolated
  kPoseInvalidSample = 1u << 1,  ///< this sample was flagged invalid; its motion was bridged
  kPoseSlipSuspected = 1u << 2,  ///< the bridge suspects slip (status bit 1)
  kPoseDiscontinuity = 1u << 3,  ///< a gap too long to bridge: motion in it is unknown
};

/// Rigid pose as plain numbers (drivers do not depend on Eigen). Hamilton quaternion.
struct Pose3 {
  double x_m = 0, y_m = 0, z_m = 0;
  double qw = 1, qx = 0, qy = 0, qz = 0;
};

struct OdometryPose {
  UnixTime stamp;                 ///< host clock, end of the sample interval
  std::uint32_t sample_time_us = 0;
  std::uint8_t sequence = 0;
  std::uint8_t flags = 0;         ///< PoseFlag bits
  Pose3 T_odom_base;
  /// Motion of this step (including any bridged part), for building odometry factors.
  Pose3 T_previous_current;
  double step_duration_s = 0;
};

struct OdometryIntegratorConfig {
  double nominal_period_s = 0.02;  ///< 50 Hz per the DBC's GenMsgCycleTime
  Duration max_bridge = Duration::FromSeconds(1.0);
  ClockOffsetFilter::Config clock;
  Status Validate() const;
};

struct OdometryIntegratorStats {
  std::uint64_t samples = 0;          ///< accepted into the trajectory
  std::uint64_t gaps = 0;             ///< sequence gaps seen
  std::uint64_t missing_samples = 0;  ///< samples lost inside those gaps
  std::uint64_t bridged = 0;          ///< gaps and invalid samples whose motion was bridged
  std::uint64_t discontinuities = 0;  ///< gaps longer than max_bridge
  std::uint64_t invalid_samples = 0;
  std::uint64_t slip_samples = 0;
  std::uint64_t duplicates = 0;       ///< same sequence and time again: rejected
  std::uint64_t out_of_order = 0;     ///< sample time went backwards: rejected
  std::uint64_t clock_resets = 0;
  double bridged_seconds = 0;
};

class OdometryIntegrator {
 public:
  static Expected<OdometryIntegrator> Create(const OdometryIntegratorConfig& config);

  /// Integrates one sample. kOutOfOrder (counted) for a duplicate or a sample older than the
  /// last one; the trajectory is then unchanged.
  Expected<OdometryPose> Add(const OdomSample& sample);

  const OdometryIntegratorStats& stats() const { return stats_; }
  bool started() const { return started_; }

 private:
  explicit OdometryIntegrator(const OdometryIntegratorConfig& config)
      : config_(config), clock_(config.clock) {}

  struct Twist {  // body-frame velocities of one sample
    double vx = 0, vy = 0, vz = 0, wroll = 0, wpitch = 0, wyaw = 0;
  };

  static Pose3 Integrate(const Twist& twist, double duration_s, double period_s);

  OdometryIntegratorConfig config_;
  ClockOffsetFilter clock_;
  bool started_ = false;
  std::uint8_t last_sequence_ = 0;
  std::uint32_t last_sample_time_us_ = 0;
  std::int64_t unwrapped_us_ = 0;
  Twist last_twist_;
  double period_estimate_s_ = 0;
  Pose3 pose_;
  OdometryIntegratorStats stats_;
};

/// Composition helpers on Pose3 (exposed for tests and tools).
Pose3 Compose(const Pose3& a, const Pose3& b);
Pose3 PoseFromDelta(double dx_m, double dy_m, double dz_m, double droll_rad, double dpitch_rad,
                    double dyaw_rad);

}  // namespace msgraphs::drivers::can_odometry
