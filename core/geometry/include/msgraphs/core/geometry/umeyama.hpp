// SPDX-License-Identifier: MIT
// Least-squares rigid alignment of two point sets (Umeyama 1991, without scale): the transform
// T minimising sum ||b_i - T a_i||^2. Used to compare trajectories (ATE) and maps.
#pragma once

#include <Eigen/Geometry>
#include <span>

#include "msgraphs/base/expected.hpp"

namespace msgraphs::core {

/// kDegenerate for fewer than 3 pairs or collinear points (the rotation about their line is
/// then undetermined); kInvalidArgument for different sizes.
Expected<Eigen::Isometry3d> AlignUmeyama(std::span<const Eigen::Vector3d> a, std::span<const Eigen::Vector3d> b);

}  // namespace msgraphs::core
