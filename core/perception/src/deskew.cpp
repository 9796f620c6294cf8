// SPDX-License-Identifier: MIT
#include "msgraphs/core/perception/deskew.hpp"

#include <array>
#include <cmath>

#include "msgraphs/core/geometry/se3.hpp"

namespace msgraphs::core {

Status DeskewToEnd(std::span<Eigen::Vector3f> points, std::span<const float> time_s, double duration_s,
                   const Eigen::Isometry3d& T_start_end) {
  if (points.size() != time_s.size()) return Error{Errc::kInvalidArgument, "deskew: one time per point"};
  if (!(duration_s > 0.0) || !std::isfinite(duration_s)) return Error{Errc::kInvalidArgument, "deskew: duration must be > 0"};
  if (!IsValidRigidTransform(T_start_end)) return Error{Errc::kInvalidArgument, "deskew: motion is not a rigid transform"};
  constexpr int kSlots = 256;
  // T_end_t = T_end_start * T_start_t, with T_start_t = Exp(alpha * Log(T_start_end)).
  const Vector6d xi = Se3Log(T_start_end);
  const Eigen::Isometry3d T_end_start = T_start_end.inverse();
  std::array<Eigen::Matrix<float, 3, 4>, kSlots + 1> table;
  for (int s = 0; s <= kSlots; ++s) {
    const Eigen::Isometry3d T = T_end_start * Se3Exp(xi * (static_cast<double>(s) / kSlots));
    table[static_cast<std::size_t>(s)] = T.matrix().topRows<3>().cast<float>();
  }
  const double scale = kSlots / duration_s;
  for (std::size_t i = 0; i < points.size(); ++i) {
    double slot = std::round(static_cast<double>(time_s[i]) * scale);
    if (!(slot >= 0.0)) slot = 0.0;  // NaN too
    if (slot > kSlots) slot = kSlots;
    const auto& M = table[static_cast<std::size_t>(slot)];
    points[i] = M.leftCols<3>() * points[i] + M.col(3);
  }
  return Ok();
}

}  // namespace msgraphs::core
