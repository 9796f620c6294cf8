// SPDX-License-Identifier: MIT
// Motion compensation of one sweep: each point, measured at time t in the sensor frame of that
// instant, is moved into the sensor frame at the end of the sweep. Transforms are precomputed
// for 256 time slots, so the per-point cost is one lookup and one transform.
//
// Two motion models: constant velocity over the sweep (one transform, start to end), or the
// sensor's trajectory sampled at evenly spaced instants across the sweep (interpolated between
// them). The second is what a legged robot needs: Spot's body rocks in roll and pitch at its
// step rate (about 2 Hz, a few degrees), so over one 0.1 s sweep the rotation is far from
// uniform; with constant velocity the middle of a sweep is tilted by up to A w^2 T^2 / 8
// (0.5 degrees for 3 degrees at 2 Hz: 9 cm at 10 m), which scan matching then absorbs as a
// roll or pitch error of its own. Odometry at 50 Hz resolves it.
#pragma once

#include <Eigen/Geometry>
#include <span>

#include "msgraphs/base/expected.hpp"

namespace msgraphs::core {

/// `time_s[i]` is point i's time after the sweep start, within [0, duration_s]. Points are
/// rewritten in place. kInvalidArgument for mismatched sizes, a non-positive duration or a
/// non-rigid transform; times outside the sweep are clamped.
Status DeskewToEnd(std::span<Eigen::Vector3f> points, std::span<const float> time_s, double duration_s,
                   const Eigen::Isometry3d& T_start_end);

/// As above, with the sensor's pose at `T_end_at.size()` evenly spaced instants: T_end_at[k] is
/// the sensor at time k * duration_s / (n - 1) in the sensor frame at the sweep's end (so the
/// last is the identity). Between two instants the motion is interpolated on SE(3). At least 2
/// and at most 257 poses; kInvalidArgument otherwise, or for a non-rigid one.
Status DeskewToEnd(std::span<Eigen::Vector3f> points, std::span<const float> time_s, double duration_s,
                   std::span<const Eigen::Isometry3d> T_end_at);

}  // namespace msgraphs::core
