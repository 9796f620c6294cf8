// SPDX-License-Identifier: MIT
// Sparsification's plane observations (docs/s-graph.md, "Sparsification"): a removed keyframe's
// observation of a plane is carried to a neighbour t through the hop between them, as if t had
// made it, and fused with t's own observation of the same plane when t has one.
//
// The measurement (normal n_v, offset d_v, covariance over (alpha, beta, delta_d) along the
// residual's basis u_v, v_v) in t's frame, with (R, p) = T_t_v:
//   n_t = R n_v,  u_t = R u_v,  v_t = R v_v,  d_t = d_v - n_t.p.
// Its covariance to first order: J_z Sigma_v J_z' + J_hop Sigma_hop J_hop', with J_z taking the
// measurement's perturbation to t's coordinates (a tilted normal moves the offset by its tilt
// along p) and J_hop the right perturbation [delta_p; delta_theta] of T_t_v:
//   J_z   = [1 0 0; 0 1 0; -u_t.p  -v_t.p  1]
//   J_hop = [0', (n_v x u_v)'; 0', (n_v x v_v)'; -n_v', -(n_v x R'p)'].
#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

#include "s_graph_impl.hpp"

namespace msgraphs::core {
namespace {

// Two true measurements of one plane differ by more than this (their difference's squared
// Mahalanobis length, 3 degrees of freedom) once in a thousand: the chi-square(3) quantile at
// 0.999. Beyond it one of them is wrong, and fusing would hide which: they stay apart and the
// robust kernel judges each.
constexpr double kFuseGateChi2 = 16.27;

bool Covariance3(const Eigen::Matrix3d& information, Eigen::Matrix3d& covariance) {
  const Eigen::LLT<Eigen::Matrix3d> llt(information);
  if (!information.allFinite() || llt.info() != Eigen::Success) return false;
  covariance = llt.solve(Eigen::Matrix3d::Identity());
  covariance = 0.5 * (covariance + covariance.transpose()).eval();
  return covariance.allFinite();
}

// The upper root of the inverse of `covariance` (r'r = e' Sigma^-1 e), as AddPlaneObservation
// stores it; false when not positive definite.
bool SqrtInformation3(const Eigen::Matrix3d& covariance, Eigen::Matrix3d& sqrt_information) {
  Eigen::Matrix3d information;
  if (!Covariance3(covariance, information)) return false;
  const Eigen::LLT<Eigen::Matrix3d> llt(information);
  if (llt.info() != Eigen::Success) return false;
  sqrt_information = llt.matrixU();
  return sqrt_information.allFinite();
}

// A plane measurement in the residual's terms with its normal made explicit.
struct Measured {
  Eigen::Vector3d n, u, v;
  double d = 0;
  Eigen::Matrix3d covariance;  // over (alpha, beta, delta_d) along u, v
};

// The residual's measurement: u, v span it; its normal is the side the map plane is seen from.
bool Read(const sgraph::PlaneResidual& z, const Eigen::Vector3d& n_predicted, Measured& m) {
  m.u = z.basis_u;
  m.v = z.basis_v;
  m.d = z.d_measured;
  m.n = z.basis_u.cross(z.basis_v).normalized();
  if (m.n.dot(n_predicted) < 0) m.n = -m.n;
  return m.n.allFinite() &&
         Covariance3(z.sqrt_information.transpose() * z.sqrt_information, m.covariance);
}

// `b` expressed in `a`'s coordinates (a's normal tilted by (alpha, beta) along a's basis, a's
// offset moved by delta_d), and b's covariance taken there.
void InCoordinatesOf(const Measured& a, const Measured& b, Eigen::Vector3d& x, Eigen::Matrix3d& covariance) {
  x << a.u.dot(b.n), a.v.dot(b.n), b.d - a.d;
  Eigen::Matrix3d M = Eigen::Matrix3d::Zero();
  M << a.u.dot(b.u), a.u.dot(b.v), 0, a.v.dot(b.u), a.v.dot(b.v), 0, 0, 0, 1;
  covariance = M * b.covariance * M.transpose();
}

// Two agreeing measurements of one plane in one frame, fused in `a`'s coordinates with their
// summed information; the basis follows the fused normal (Gram-Schmidt from a's, so it keeps
// a's orientation). False when they disagree beyond kFuseGateChi2 or a matrix is singular.
bool Fuse(const Measured& a, const Measured& b, Measured& fused) {
  Eigen::Vector3d x;
  Eigen::Matrix3d covariance_b;
  InCoordinatesOf(a, b, x, covariance_b);
  const Eigen::LLT<Eigen::Matrix3d> apart(a.covariance + covariance_b);
  if (apart.info() != Eigen::Success || x.dot(apart.solve(x)) > kFuseGateChi2) return false;
  Eigen::Matrix3d information_a, information_b, covariance;
  if (!Covariance3(a.covariance, information_a) || !Covariance3(covariance_b, information_b) ||
      !Covariance3(information_a + information_b, covariance))
    return false;
  const Eigen::Vector3d step = covariance * (information_b * x);
  fused.n = (a.n + step.x() * a.u + step.y() * a.v).normalized();
  fused.d = a.d + step.z();
  fused.u = (a.u - a.u.dot(fused.n) * fused.n).normalized();
  fused.v = (a.v - a.v.dot(fused.n) * fused.n - a.v.dot(fused.u) * fused.u).normalized();
  Eigen::Matrix3d M = Eigen::Matrix3d::Zero();  // a's coordinates to the fused basis'
  M << fused.u.dot(a.u), fused.u.dot(a.v), 0, fused.v.dot(a.u), fused.v.dot(a.v), 0, 0, 0, 1;
  fused.covariance = M * covariance * M.transpose();
  return fused.n.allFinite() && fused.u.allFinite() && fused.v.allFinite() && std::isfinite(fused.d);
}

}  // namespace

Expected<std::int32_t> SGraph::Impl::AddPlaneFactor(std::uint32_t keyframe,
                                                    std::uint32_t plane,
                                                    const sgraph::PlaneResidual& z) {
  auto slot = NewFactor(FactorKind::kPlane, keyframe, plane);
  if (!slot) return slot.error();
  PlaneNode& p = planes[plane];
  // An observation by a keyframe the plane's held sum already covers: the sum is taken afresh.
  if (keyframes[keyframe].stamp_s < p.held_before_s) p.held_epoch = 0;
  EnsurePlaneInProblem(p);
  KeyframeNode& k = keyframes[keyframe];
  Bind(*slot, problem->AddResidualBlock(new sgraph::PlaneCost(new sgraph::PlaneResidual(z)),
                                        huber_plane.get(), k.q, k.t, p.n, p.d));
  ++stats.plane_factors;
  ++p.info.live_observations;
  return *slot;
}

bool SGraph::Impl::CarryPlaneObservation(std::int32_t slot,
                                         std::uint32_t t,
                                         const Eigen::Isometry3d& T_t_v,
                                         const Matrix6d& hop_covariance,
                                         bool& fused) {
  fused = false;
  const FactorRecord f = factors[static_cast<std::size_t>(slot)];
  MSGRAPHS_ASSERT(f.active && f.kind == FactorKind::kPlane, "not a plane observation");
  const std::uint32_t v = f.a, plane = f.b;
  PlaneNode& p = planes[plane];
  const Eigen::Vector3d n_map(p.n[0], p.n[1], p.n[2]);
  const auto& z = static_cast<const sgraph::PlaneCost*>(problem->GetCostFunctionForResidualBlock(f.id))->functor();
  Measured at_v, at_t;
  bool ok = Read(z, Pose(v).linear().transpose() * n_map, at_v);
  const Eigen::Matrix3d R = T_t_v.linear();
  const Eigen::Vector3d p_tv = T_t_v.translation();
  at_t.n = R * at_v.n;
  at_t.u = R * at_v.u;
  at_t.v = R * at_v.v;
  at_t.d = at_v.d - at_t.n.dot(p_tv);
  Eigen::Matrix3d J_z = Eigen::Matrix3d::Identity();
  J_z(2, 0) = -at_t.u.dot(p_tv);
  J_z(2, 1) = -at_t.v.dot(p_tv);
  Eigen::Matrix<double, 3, 6> J_hop = Eigen::Matrix<double, 3, 6>::Zero();
  J_hop.block<1, 3>(0, 3) = at_v.n.cross(at_v.u).transpose();
  J_hop.block<1, 3>(1, 3) = at_v.n.cross(at_v.v).transpose();
  J_hop.block<1, 3>(2, 0) = -at_v.n.transpose();
  J_hop.block<1, 3>(2, 3) = -at_v.n.cross(R.transpose() * p_tv).transpose();
  if (ok) {
    at_t.covariance = J_z * at_v.covariance * J_z.transpose() + J_hop * hop_covariance * J_hop.transpose();
    at_t.covariance = 0.5 * (at_t.covariance + at_t.covariance.transpose()).eval();
  }
  // t's own observation of the plane that agrees with the carried one (a keyframe may hold two:
  // segments of one wall).
  std::int32_t own = kNone;
  Measured at_t_own, merged;
  if (ok) {
    const Eigen::Vector3d n_predicted = Pose(t).linear().transpose() * n_map;
    problem->GetResidualBlocksForParameterBlock(keyframes[t].q, &scratch_residuals);
    for (ceres::ResidualBlockId id : scratch_residuals) {
      const std::int32_t s = residual_index.Find(id);
      if (s == sgraph::ResidualIndex::kAbsent) continue;
      const FactorRecord& g = factors[static_cast<std::size_t>(s)];
      if (!g.active || g.kind != FactorKind::kPlane || g.a != t || g.b != plane) continue;
      const auto& zt = static_cast<const sgraph::PlaneCost*>(problem->GetCostFunctionForResidualBlock(id))->functor();
      if (Read(zt, n_predicted, at_t_own) && Fuse(at_t_own, at_t, merged) &&
          (own == kNone || s < own)) {  // the lowest slot: not Ceres' hash order
        own = s;
      }
    }
    if (own != kNone) {  // fused again with the one chosen (Read / Fuse are pure)
      const FactorRecord& g = factors[static_cast<std::size_t>(own)];
      const auto& zt = static_cast<const sgraph::PlaneCost*>(problem->GetCostFunctionForResidualBlock(g.id))->functor();
      ok = Read(zt, Pose(t).linear().transpose() * n_map, at_t_own) && Fuse(at_t_own, at_t, merged);
    }
  }
  const Measured& put = own != kNone ? merged : at_t;
  sgraph::PlaneResidual carried{put.u, put.v, put.d, Eigen::Matrix3d::Zero()};
  ok = ok && SqrtInformation3(put.covariance, carried.sqrt_information);
  // Both are removed before the replacement is added, so the factor store has room and the
  // replacement takes t's slot (the free list is last in, first out): the order the
  // rebuilt-problem test (SGraphOrder.*) holds bit for bit. The add cannot fail after two
  // removals; were it to, t's observation would be counted as dropped with v's. The plane's
  // live count dips to zero in between only when the replacement restores it.
  const std::uint64_t unobserved_before = stats.planes_unobserved;
  RemoveFactor(slot);
  if (!ok) return false;
  if (own != kNone) RemoveFactor(own);
  if (!AddPlaneFactor(t, plane, carried)) {
    if (own != kNone) ++stats.sparsify_planes_dropped;
    return false;
  }
  stats.planes_unobserved = unobserved_before;
  // t observes the plane now: a plane moves in the local solve when its newest observer does.
  p.info.last_observed_s = std::max(p.info.last_observed_s, keyframes[t].stamp_s);
  fused = own != kNone;
  return true;
}

}  // namespace msgraphs::core
