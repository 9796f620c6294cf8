// SPDX-License-Identifier: MIT
#include "msgraphs/core/collab/free_space_conflict.hpp"

#include <algorithm>
#include <cmath>

namespace msgraphs::core {
namespace {

bool NearWall(const WallIndex& walls, const Eigen::Vector2d& p, double distance_m) {
  for (const AlignWall& w : walls.walls()) {
    if (std::fabs(w.n.dot(p) + w.d) > distance_m) continue;
    const Eigen::Vector2d u(-w.n.y(), w.n.x());
    const double s = u.dot(p), s0 = std::min(u.dot(w.a), u.dot(w.b)), s1 = std::max(u.dot(w.a), u.dot(w.b));
    if (s >= s0 - distance_m && s <= s1 + distance_m) return true;
  }
  return false;
}

}  // namespace

Status FreeSpaceConflictConfig::Validate() const {
  if (!(clearance_m > 0) || !(sample_step_m > 0.01 && sample_step_m <= 1.0) || !(opening_margin_m >= 0) ||
      !(door_solid_share > 0 && door_solid_share <= 1) || !(door_wall_distance_m > 0)) {
    return Error{Errc::kInvalidConfig, "free-space conflict: distances and shares must be positive"};
  }
  return Ok();
}

FreeSpaceConflict ConflictOf(const WallIndex& walls_x, const FreeSpaceSummary& summary_x,
                             const PlanarTransform& T_y_x, const WallIndex& walls_y,
                             const FreeSpaceSummary& summary_y, const FreeSpaceConflictConfig& c) {
  FreeSpaceConflict out;
  if (summary_y.empty()) return out;
  const double step = c.sample_step_m;
  for (const AlignWall& w : walls_x.walls()) {
    const Eigen::Vector2d a = T_y_x * w.a, b = T_y_x * w.b;
    const auto n = static_cast<int>(std::ceil(w.length_m / step));
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector2d p = a + (b - a) * ((i + 0.5) / n);
      if (static_cast<double>(summary_y.clearance_m(p)) < c.clearance_m) continue;
      if (summary_y.NearOpening(p, c.opening_margin_m)) continue;
      out.walls_in_free_m += w.length_m / n;
    }
  }
  for (const Opening& o : summary_x.openings()) {
    const Eigen::Vector2d a = T_y_x * o.a, b = T_y_x * o.b;
    const double width = (b - a).norm();
    const auto n = std::max(1, static_cast<int>(std::ceil(width / step)));
    double solid = 0;
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector2d p = a + (b - a) * ((i + 0.5) / n);
      if (summary_y.state_at(p) != SummaryCell::kOccupied) continue;
      if (summary_y.NearOpening(p, c.opening_margin_m)) continue;
      if (!NearWall(walls_y, p, c.door_wall_distance_m)) continue;
      solid += width / n;
    }
    if (solid >= c.door_solid_share * width) out.openings_on_solid_m += solid;
  }
  return out;
}

}  // namespace msgraphs::core
