// SPDX-License-Identifier: MIT
// Spot's trot seen from the body frame: while it walks (or turns in place) the body bobs once
// per step and rocks in roll and pitch, so the base frame is not level. The oscillation grows
// in and out smoothly over about a step when the robot starts or stops, and is exactly zero
// while it stands still. The step rate rises with speed (slow walk to full trot).
//
//   z     = base + bob_m    * e(t) * cos(phi(t))
//   pitch =        pitch_rad * e(t) * sin(phi(t) + pitch_phase)       (once per step)
//   roll  =        roll_rad  * e(t) * sin(phi(t) / 2 + roll_phase)    (once per stride: the body
//                                                                      sways left, then right)
// with phi the step phase (d phi / dt = 2 pi f_step) and e in [0, 1] the gait envelope. Both are
// sampled with the planar trajectory and interpolated as cubic Hermite curves, so the pose has
// continuous first derivatives.
#pragma once

#include <cstdint>
#include <vector>

namespace msgraphs::sim {

struct PlanarPose;

/// The ranges each robot's gait is drawn from: documented configuration values, the benchmark's
/// model of a trot (a few cm of bob, a few degrees of rocking, 1.5-2.5 steps per second), not
/// measured on a real Spot.
struct GaitConfig {
  bool enabled = true;
  double bob_min_m = 0.01, bob_max_m = 0.03;        ///< peak height oscillation
  double roll_min_deg = 1.0, roll_max_deg = 3.0;    ///< peak roll
  double pitch_min_deg = 1.0, pitch_max_deg = 3.0;  ///< peak pitch
  double step_rate_slow_hz = 1.5;                   ///< stepping in place, slowest walk
  double step_rate_fast_hz = 2.5;                   ///< at full_speed_mps and above
  double full_speed_mps = 1.0;
  /// Speed and turn rate at which the legs are fully trotting (below: the envelope ramps).
  double trot_speed_mps = 0.25;
  double trot_turn_rate_rps = 0.3;
  /// Half-width of the smoothing window of the envelope and the speed: about a step.
  double settle_s = 0.4;
};

/// One robot's gait, drawn from GaitConfig.
struct GaitParams {
  double bob_m = 0, roll_rad = 0, pitch_rad = 0;
  double roll_phase_rad = 0, pitch_phase_rad = 0, start_phase_rad = 0;
  GaitConfig config;
  static GaitParams Draw(const GaitConfig& config, std::uint64_t seed, int robot);
};

/// The gait offsets of the base frame at one instant.
struct GaitOffsets {
  double z_m = 0, roll_rad = 0, pitch_rad = 0;
};

/// Per-sample gait state along a trajectory (allocates at Build).
class GaitTrack {
 public:
  void Build(const std::vector<PlanarPose>& samples, double dt_s, const GaitParams& params);
  bool empty() const { return envelope_.empty(); }
  /// Offsets at sample position u = t / dt (clamped to the samples).
  GaitOffsets At(double u) const;
  const GaitParams& params() const { return params_; }

 private:
  GaitParams params_;
  double dt_s_ = 0.01;
  std::vector<double> phase_rad_, rate_rad_s_, envelope_;
};

}  // namespace msgraphs::sim
