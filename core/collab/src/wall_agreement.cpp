// SPDX-License-Identifier: MIT
#include "msgraphs/core/collab/wall_agreement.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

namespace msgraphs::core {
namespace {

Eigen::Vector2d Perp(const Eigen::Vector2d& v) { return {-v.y(), v.x()}; }

// Walks b's walls laid into a's frame and calls visit(a_wall, q0, q1) for every overlap, with
// q0, q1 the overlap's ends on b's transformed wall (a's frame). Each b wall counts once in
// total: overlaps beyond its length are cut.
template <typename Visit>
void ForEachOverlap(const WallIndex& a, const WallIndex& b, const PlanarTransform& T,
                    const WallAgreementConfig& c, Visit&& visit) {
  const Eigen::Matrix2d R = T.R();
  for (const AlignWall& w : b.walls()) {
    const Eigen::Vector2d n = R * w.n;
    const Eigen::Vector2d pa = R * w.a + T.t_m, pb = R * w.b + T.t_m;
    const double d = -n.dot(0.5 * (pa + pb));
    double left = w.length_m;
    a.ForEachNear(n, d, c.angle_rad, c.offset_m, [&](const AlignWall& v) {
      if (left <= 0) return;
      const Eigen::Vector2d u = Perp(v.n);
      const double v0 = std::min(u.dot(v.a), u.dot(v.b)), v1 = std::max(u.dot(v.a), u.dot(v.b));
      const double s0 = u.dot(pa), s1 = u.dot(pb);
      const double w0 = std::min(s0, s1), w1 = std::max(s0, s1);
      const double lo = std::max(v0, w0), hi = std::min(v1, w1);
      if (!(hi > lo)) return;
      const double length = std::min(hi - lo, left);
      left -= length;
      // The overlap's ends on b's wall (a's frame).
      const double span = s1 - s0;
      if (std::fabs(span) < 1e-9) return;
      const Eigen::Vector2d q0 = pa + (pb - pa) * ((lo - s0) / span);
      const Eigen::Vector2d q1 = pa + (pb - pa) * ((lo + length - s0) / span);
      visit(v, q0, q1, length);
    });
  }
}

}  // namespace

Status WallAgreementConfig::Validate() const {
  if (!(angle_rad > 0 && angle_rad < 0.5) || !(offset_m > 0 && offset_m < 2))
    return Error{Errc::kInvalidConfig, "wall agreement: angle in (0, 0.5) rad, offset in (0, 2) m"};
  return Ok();
}

WallAgreement ScoreAgreement(const WallIndex& a, const WallIndex& b, const PlanarTransform& T_a_b,
                             const WallAgreementConfig& config) {
  WallAgreement out;
  ForEachOverlap(a, b, T_a_b, config,
                 [&](const AlignWall& v, const Eigen::Vector2d&, const Eigen::Vector2d&, double length) {
                   out.agreement_m += length;
                   out.information += length * v.n * v.n.transpose();
                   ++out.pairs;
                 });
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(out.information, Eigen::EigenvaluesOnly);
  out.constraint_m = std::max(0.0, eig.eigenvalues()(0));
  return out;
}

PlanarTransform RefineTransform(const WallIndex& a, const WallIndex& b, PlanarTransform T,
                                const WallAgreementConfig& config, int iterations) {
  for (int it = 0; it < iterations; ++it) {
    // Left perturbation: q -> q + dyaw * perp(q) + dt; residual n_a . q + d_a at both ends.
    Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
    Eigen::Vector3d g = Eigen::Vector3d::Zero();
    ForEachOverlap(a, b, T, config,
                   [&](const AlignWall& v, const Eigen::Vector2d& q0, const Eigen::Vector2d& q1, double length) {
                     for (const Eigen::Vector2d& q : {q0, q1}) {
                       const double r = v.n.dot(q) + v.d;
                       const Eigen::Vector3d J(v.n.dot(Perp(q)), v.n.x(), v.n.y());
                       H += 0.5 * length * J * J.transpose();
                       g += 0.5 * length * J * r;
                     }
                   });
    if (H.trace() <= 0) break;
    // Damped: a direction the walls do not constrain stays where it was.
    Eigen::Matrix3d D = H;
    D.diagonal() += 1e-3 * H.diagonal() + Eigen::Vector3d::Constant(1e-6 * H.diagonal().maxCoeff());
    const Eigen::Vector3d delta = -D.ldlt().solve(g);
    if (!delta.allFinite()) break;
    const PlanarTransform step{delta(0), delta.tail<2>()};
    T = step * T;
    if (std::fabs(delta(0)) < 1e-6 && delta.tail<2>().norm() < 1e-5) break;
  }
  return T;
}

}  // namespace msgraphs::core
