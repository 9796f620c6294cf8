// SPDX-License-Identifier: MIT
#include "msgraphs/core/collab/hypothesis_check.hpp"

#include <algorithm>
#include <cmath>

namespace msgraphs::core {

Status HypothesisCheckConfig::Validate() const {
  if (!(wall_angle_rad > 0) || !(wall_offset_m > 0) || !(margin_ratio >= 1) ||
      !(margin_m >= 0)) {
    return Error{Errc::kInvalidConfig,
                 "hypothesis check: wall tolerances must be positive, margin_ratio >= 1"};
  }
  return Ok();
}

double WallAgreement_m(const DistilledGraph& a,
                       const DistilledGraph& b,
                       const Eigen::Isometry3d& T_a_b,
                       const HypothesisCheckConfig& config) {
  const double cos_angle = std::cos(config.wall_angle_rad);
  const Eigen::Matrix3d& R = T_a_b.linear();
  const Eigen::Vector3d& t = T_a_b.translation();
  double total_m = 0;
  for (const DistilledWall& wb : b.walls) {
    const Eigen::Vector3d n = R * wb.normal;
    const double d = wb.d - n.dot(t);  // n.p + d = 0 in a's frame
    // The wall's ends in a's frame (extents are horizontal; z does not matter for them).
    const Eigen::Vector2d b0 = (T_a_b * Eigen::Vector3d(wb.a.x(), wb.a.y(), 0)).head<2>();
    const Eigen::Vector2d b1 = (T_a_b * Eigen::Vector3d(wb.b.x(), wb.b.y(), 0)).head<2>();
    double best_m = 0;
    for (const DistilledWall& wa : a.walls) {
      if (n.dot(wa.normal) < cos_angle || std::fabs(d - wa.d) > config.wall_offset_m) continue;
      const Eigen::Vector2d along = wa.b - wa.a;
      const double length_m = along.norm();
      if (!(length_m > 1e-6)) continue;
      const Eigen::Vector2d u = along / length_m;
      // Both extents as intervals along a's wall, a's from 0 to its length.
      const double s0 = u.dot(b0 - wa.a), s1 = u.dot(b1 - wa.a);
      const double overlap_m = std::min(length_m, std::max(s0, s1)) - std::max(0.0, std::min(s0, s1));
      best_m = std::max(best_m, overlap_m);
    }
    total_m += best_m;
  }
  return total_m;
}

int ChooseHypothesis(std::span<const std::size_t> match_counts,
                     std::span<const double> agreement_m,
                     std::size_t min_consistent,
                     const HypothesisCheckConfig& config) {
  const std::size_t n = std::min(match_counts.size(), agreement_m.size());
  if (n == 0 || match_counts[0] < min_consistent) return -1;
  if (n == 1) return 0;
  std::size_t best = 0, second = 1;
  if (agreement_m[1] > agreement_m[0]) std::swap(best, second);
  for (std::size_t i = 2; i < n; ++i) {
    if (agreement_m[i] > agreement_m[best]) {
      second = best;
      best = i;
    } else if (agreement_m[i] > agreement_m[second]) {
      second = i;
    }
  }
  if (agreement_m[best] >= config.margin_ratio * agreement_m[second] + config.margin_m)
    return match_counts[best] >= min_consistent ? static_cast<int>(best) : -1;
  // The walls cannot tell: more matches can, a tie cannot.
  return match_counts[0] > match_counts[1] ? 0 : -1;
}

}  // namespace msgraphs::core
