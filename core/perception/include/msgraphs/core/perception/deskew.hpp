// SPDX-License-Identifier: MIT
// Motion compensation of one sweep: each point, measured at time t in the sensor frame of that
// instant, is moved into the sensor frame at the end of the sweep, assuming constant velocity
// over the sweep (the motion T_start_end comes from odometry). Transforms are precomputed for
// 256 time slots, so the per-point cost is one lookup and one transform.
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

}  // namespace msgraphs::core
