// SPDX-License-Identifier: MIT
#include "msgraphs/core/perception/deskew.hpp"

#include <array>
#include <cmath>

#include "msgraphs/core/geometry/se3.hpp"

namespace msgraphs::core {
namespace {

constexpr int kSlots = 256;
using SlotTable = std::array<Eigen::Matrix<float, 3, 4>, kSlots + 1>;

Status CheckInputs(std::span<Eigen::Vector3f> points, std::span<const float> time_s, double duration_s) {
  if (points.size() != time_s.size()) return Error{Errc::kInvalidArgument, "deskew: one time per point"};
  if (!(duration_s > 0.0) || !std::isfinite(duration_s)) return Error{Errc::kInvalidArgument, "deskew: duration must be > 0"};
  return Ok();
}

void Apply(const SlotTable& table, std::span<Eigen::Vector3f> points, std::span<const float> time_s,
           double duration_s) {
  const double scale = kSlots / duration_s;
  for (std::size_t i = 0; i < points.size(); ++i) {
    double slot = std::round(static_cast<double>(time_s[i]) * scale);
    if (!(slot >= 0.0)) slot = 0.0;  // NaN too
    if (slot > kSlots) slot = kSlots;
    const auto& M = table[static_cast<std::size_t>(slot)];
    points[i] = M.leftCols<3>() * points[i] + M.col(3);
  }
}

}  // namespace

Status DeskewToEnd(std::span<Eigen::Vector3f> points, std::span<const float> time_s, double duration_s,
                   const Eigen::Isometry3d& T_start_end) {
  if (auto s = CheckInputs(points, time_s, duration_s); !s) return s;
  if (!IsValidRigidTransform(T_start_end)) return Error{Errc::kInvalidArgument, "deskew: motion is not a rigid transform"};
  // T_end_t = T_end_start * T_start_t, with T_start_t = Exp(alpha * Log(T_start_end)).
  const Vector6d xi = Se3Log(T_start_end);
  const Eigen::Isometry3d T_end_start = T_start_end.inverse();
  SlotTable table;
  for (int s = 0; s <= kSlots; ++s) {
    const Eigen::Isometry3d T = T_end_start * Se3Exp(xi * (static_cast<double>(s) / kSlots));
    table[static_cast<std::size_t>(s)] = T.matrix().topRows<3>().cast<float>();
  }
  Apply(table, points, time_s, duration_s);
  return Ok();
}

Status DeskewToEnd(std::span<Eigen::Vector3f> points, std::span<const float> time_s, double duration_s,
                   std::span<const Eigen::Isometry3d> T_end_at) {
  if (auto s = CheckInputs(points, time_s, duration_s); !s) return s;
  if (T_end_at.size() < 2 || T_end_at.size() > kSlots + 1)
    return Error{Errc::kInvalidArgument, "deskew: 2 to 257 poses across the sweep"};
  for (const Eigen::Isometry3d& T : T_end_at) {
    if (!IsValidRigidTransform(T)) return Error{Errc::kInvalidArgument, "deskew: a pose is not a rigid transform"};
  }
  const auto intervals = static_cast<double>(T_end_at.size() - 1);
  SlotTable table;
  for (int s = 0; s <= kSlots; ++s) {
    // Slot s lies between poses k and k + 1, a fraction `a` of the way.
    const double u = static_cast<double>(s) / kSlots * intervals;
    const auto k = std::min(static_cast<std::size_t>(u), T_end_at.size() - 2);
    const double a = u - static_cast<double>(k);
    const Eigen::Isometry3d& T0 = T_end_at[k];
    const Eigen::Isometry3d T = T0 * Se3Exp(a * Se3Log(T0.inverse() * T_end_at[k + 1]));
    table[static_cast<std::size_t>(s)] = T.matrix().topRows<3>().cast<float>();
  }
  Apply(table, points, time_s, duration_s);
  return Ok();
}

}  // namespace msgraphs::core
