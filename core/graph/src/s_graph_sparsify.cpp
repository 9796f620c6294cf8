// SPDX-License-Identifier: MIT
// S-Graph sparsification: one keyframe out when the keyframe store is full (docs/s-graph.md),
// or the one a caller names (SGraph::RemoveKeyframe).
//
// The victim's neighbours p and n are joined by the composition of its two chain hops, and every
// other relative factor on it (a loop closure) is carried to a neighbour through the hop that
// leads there, and so is every plane observation on it (s_graph_sparsify_planes.cpp). A hop
// shared by several carried factors enters each with its covariance divided by that factor's
// weight, the weights summing to one (covariance intersection): the factors are then never
// jointly more certain than the one measurement they share, whatever its correlation with
// itself. The plane observations get sparsify_plane_share of it together, the composed chain
// and the loops the rest, in equal parts within each group.
#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>
#include <span>

#include "msgraphs/base/assert.hpp"
#include "msgraphs/core/geometry/se3.hpp"
#include "s_graph_impl.hpp"

namespace msgraphs::core {
namespace {

using sgraph::Adjoint;

// Covariance of an information matrix (or the reverse), symmetrised; false when not positive
// definite.
bool Invert(const Matrix6d& m, Matrix6d& inverse) {
  if (!m.allFinite()) return false;
  const Eigen::LLT<Matrix6d> llt(m);
  if (llt.info() != Eigen::Success) return false;
  inverse = llt.solve(Matrix6d::Identity());
  inverse = 0.5 * (inverse + inverse.transpose()).eval();
  return inverse.allFinite();
}

// One side of the victim: the fused chain measurement from a keyframe to the next.
struct Hop {
  Eigen::Isometry3d Z = Eigen::Isometry3d::Identity();  // T_from_to
  Matrix6d covariance = Matrix6d::Zero();
  double log_det_information = -std::numeric_limits<double>::infinity();
  bool usable = false;
  double uses = 0;         // composed factors (the joined chain, carried loops) that rest on it
  double plane_uses = 0;   // carried plane observations that rest on it
  double chain_scale = 0;  // what each composed factor multiplies its covariance by (Share)
  double plane_scale = 0;  // and each carried plane observation
};

// The weights: equal within each group, the planes' group sparsify_plane_share of the whole
// when both groups rest on the hop.
void Share(Hop& h, double plane_share) {
  const bool both = h.uses > 0 && h.plane_uses > 0;
  h.chain_scale = both ? h.uses / (1.0 - plane_share) : h.uses;
  h.plane_scale = both ? h.plane_uses / plane_share : h.plane_uses;
}

Hop MakeHop(const KeyframeNode& to) {
  Hop h;
  h.Z = to.measurement_from_prev;
  if (to.information_from_prev.isZero(0.0)) return h;  // no measurement: the chain is cut here
  const Eigen::LLT<Matrix6d> llt(to.information_from_prev);
  if (llt.info() != Eigen::Success || !Invert(to.information_from_prev, h.covariance)) return h;
  h.log_det_information = 2.0 * llt.matrixLLT().diagonal().array().log().sum();
  h.usable = std::isfinite(h.log_det_information);
  return h;
}

enum class Via : std::uint8_t { kPrev, kNext, kNowhere };

// Which hop carries a factor between the victim and `partner`: never the one leading to the
// partner itself; otherwise the more informative one (the smaller uncertainty volume).
Via Route(std::uint32_t partner, std::uint32_t p, std::uint32_t n, const Hop& a, const Hop& b) {
  const bool to_p = partner != p && a.usable, to_n = partner != n && b.usable;
  if (to_p && to_n) return b.log_det_information >= a.log_det_information ? Via::kNext : Via::kPrev;
  if (to_n) return Via::kNext;
  if (to_p) return Via::kPrev;
  return Via::kNowhere;
}

}  // namespace

void SGraph::Impl::RelativeMeasurement(const FactorRecord& f,
                                       Eigen::Isometry3d& T_a_b,
                                       Matrix6d& information) const {
  MSGRAPHS_ASSERT(f.active && f.kind == FactorKind::kRelative, "not a relative-pose factor");
  // Every relative factor is built by AddRelative as a RelativePoseCost.
  const auto* cost =
      static_cast<const sgraph::RelativePoseCost*>(problem->GetCostFunctionForResidualBlock(f.id));
  const sgraph::RelativePoseResidual& r = cost->functor();
  T_a_b = Eigen::Isometry3d::Identity();
  T_a_b.linear() = r.q_z.toRotationMatrix();
  T_a_b.translation() = r.t_z;
  information = r.sqrt_information.transpose() * r.sqrt_information;
}

bool SGraph::Impl::AddOrFuseRelative(std::uint32_t from,
                                     std::uint32_t to,
                                     const Eigen::Isometry3d& T_from_to,
                                     const Matrix6d& information,
                                     RelativePoseKind kind,
                                     std::span<const std::uint32_t> keep_factors,
                                     bool& fused) {
  fused = false;
  // A parallel factor of the same kind: one factor with both measurements, so that loops
  // carried again and again over an endless patrol do not pile up between the same keyframes.
  // Never one the caller keeps (a loop still to be judged by its id).
  for (std::size_t i = 0; i < factor_high_water; ++i) {
    const FactorRecord& f = factors[i];
    if (!f.active || f.kind != FactorKind::kRelative || f.chain || f.relative != kind ||
        !((f.a == from && f.b == to) || (f.a == to && f.b == from))) {
      continue;
    }
    if (std::find(keep_factors.begin(), keep_factors.end(), static_cast<std::uint32_t>(i)) !=
        keep_factors.end()) {
      continue;
    }
    Eigen::Isometry3d T;
    Matrix6d info;
    RelativeMeasurement(f, T, info);
    if (f.a == to) {  // as from -> to: Sigma of T^-1 is Ad(T) Sigma Ad(T)^T
      const Matrix6d Ad_inv = Adjoint(T.inverse());
      info = (Ad_inv.transpose() * info * Ad_inv).eval();
      T = T.inverse();
    }
    Matrix6d sum = info + information;
    sum = 0.5 * (sum + sum.transpose()).eval();
    const Eigen::Isometry3d Z = sgraph::Fuse(T, info, T_from_to, information);
    RemoveFactor(static_cast<std::int32_t>(i));
    fused = static_cast<bool>(AddRelative(from, to, Z, sum, kind));
    return fused;
  }
  return static_cast<bool>(AddRelative(from, to, T_from_to, information, kind));
}

std::int32_t SGraph::Impl::WindowStart() const {
  std::int32_t window_start = newest;
  for (std::size_t i = 1; i < config.local_window_keyframes && window_start != kNone; ++i) {
    window_start = keyframes[static_cast<std::size_t>(window_start)].prev;
  }
  return window_start;
}

bool SGraph::Impl::RemovalLosesNothing(std::uint32_t v) {
  const auto p = static_cast<std::uint32_t>(keyframes[v].prev);
  const auto n = static_cast<std::uint32_t>(keyframes[v].next);
  const Hop a = MakeHop(keyframes[v]), b = MakeHop(keyframes[n]);
  if (!a.usable || !b.usable) return false;  // nothing would join the neighbours
  for (std::size_t i = 0; i < factor_high_water; ++i) {
    const FactorRecord& f = factors[i];
    if (!f.active || f.kind != FactorKind::kRelative || f.chain || (f.a != v && f.b != v))
      continue;
    if (Route(f.a == v ? f.b : f.a, p, n, a, b) == Via::kNowhere) return false;
  }
  // Plane observations go through a hop (both are usable here) unless carrying is off: then a
  // plane whose every live observation is v's would be left unmeasured (held where it is, with
  // no marginal).
  if (config.sparsify_plane_share > 0) return true;
  MarkLastObservers();
  return !keyframes[v].last_observer;
}

void SGraph::Impl::MarkLastObservers() {
  // Which keyframes are the only ones left that observe some plane (a keyframe may observe one
  // plane twice: two segments of a wall). One pass over the factors, not one per candidate;
  // the scratch lives in the nodes (sized at Init).
  for (std::size_t k = 0; k < keyframe_high_water; ++k) keyframes[k].last_observer = false;
  for (std::size_t p = 0; p < plane_count; ++p) {
    planes[p].only_observer = kNone;
    planes[p].observers_two_or_more = false;
  }
  for (std::size_t i = 0; i < factor_high_water; ++i) {
    const FactorRecord& f = factors[i];
    if (!f.active || f.kind != FactorKind::kPlane) continue;
    PlaneNode& p = planes[f.b];
    if (p.only_observer == kNone)
      p.only_observer = static_cast<std::int32_t>(f.a);
    else if (p.only_observer != static_cast<std::int32_t>(f.a))
      p.observers_two_or_more = true;
  }
  for (std::size_t p = 0; p < plane_count; ++p) {
    if (planes[p].only_observer != kNone && !planes[p].observers_two_or_more)
      keyframes[static_cast<std::size_t>(planes[p].only_observer)].last_observer = true;
  }
}

bool SGraph::Impl::Sparsify() {
  if (origin == kNone || newest == kNone) return false;
  const std::int32_t window_start = WindowStart();
  if (window_start == kNone) return false;
  MarkLastObservers();
  // The victim, cheapest loss first: no loop closure on it; then loops that can be carried
  // (a hop with a measurement to carry them through), fewest first; then the rest. Within each
  // of those, a keyframe that would leave some plane unobserved (its last observer, with no hop
  // to carry the observation through, or carrying off) after the others (a loop weighs more
  // than a plane seen once), then the shortest hop between its neighbours (the most redundant
  // keyframe). Never the origin, never in the local window.
  std::int32_t victim = kNone;
  int best_tier = 6;
  std::uint32_t best_loops = 0;
  double best_hop = 0;
  for (std::int32_t k = keyframes[static_cast<std::size_t>(origin)].next;
       k != kNone && k != window_start; k = keyframes[static_cast<std::size_t>(k)].next) {
    const KeyframeNode& node = keyframes[static_cast<std::size_t>(k)];
    if (node.prev == kNone || node.next == kNone) continue;
    // Information enters the chain only through AddRelative, which refuses any that is not
    // positive definite, so a non-zero one is a usable hop (MakeHop) without its factorisation.
    const bool carriable =
        !node.information_from_prev.isZero(0.0) ||
        !keyframes[static_cast<std::size_t>(node.next)].information_from_prev.isZero(0.0);
    // A last observer whose observations can be carried loses nothing a plane needs.
    const bool strands_a_plane = node.last_observer && !(carriable && config.sparsify_plane_share > 0);
    const int tier =
        2 * (node.loop_factors == 0 ? 0 : (carriable ? 1 : 2)) + (strands_a_plane ? 1 : 0);
    const double hop = (Pose(static_cast<std::uint32_t>(node.prev)).translation() -
                        Pose(static_cast<std::uint32_t>(node.next)).translation())
                           .norm();
    const bool better =
        tier < best_tier ||
        (tier == best_tier &&
         (node.loop_factors < best_loops || (node.loop_factors == best_loops && hop < best_hop)));
    if (better) {
      victim = k;
      best_tier = tier;
      best_loops = node.loop_factors;
      best_hop = hop;
    }
  }
  if (victim == kNone) return false;
  RemoveKeyframe(static_cast<std::uint32_t>(victim));
  ++stats.sparsified;
  return true;
}

void SGraph::Impl::RemoveKeyframe(std::uint32_t v, std::span<const std::uint32_t> keep_factors) {
  MSGRAPHS_ASSERT(ValidKeyframe(v) && keyframes[v].prev != kNone && keyframes[v].next != kNone,
                  "only a keyframe between two others is removed");
  const auto p = static_cast<std::uint32_t>(keyframes[v].prev);
  const auto n = static_cast<std::uint32_t>(keyframes[v].next);
  const bool had_loops = keyframes[v].loop_factors > 0;
  Hop a = MakeHop(keyframes[v]), b = MakeHop(keyframes[n]);  // p -> v, v -> n
  const bool compose = a.usable && b.usable;
  const auto touches = [v](const FactorRecord& f) {
    return f.active && f.kind == FactorKind::kRelative && !f.chain && (f.a == v || f.b == v);
  };
  const bool carry_planes = config.sparsify_plane_share > 0;
  const auto observes = [v](const FactorRecord& f) {
    return f.active && f.kind == FactorKind::kPlane && f.a == v;
  };
  // A plane observation is no partner keyframe: v stands for it in Route (neither neighbour).
  const Via plane_via = carry_planes ? Route(v, p, n, a, b) : Via::kNowhere;
  // 1. How many carried factors rest on each hop, and the share each gets.
  a.uses = b.uses = compose ? 1.0 : 0.0;
  for (std::size_t i = 0; i < factor_high_water; ++i) {
    const FactorRecord& f = factors[i];
    const Via via = touches(f)     ? Route(f.a == v ? f.b : f.a, p, n, a, b)
                    : observes(f) ? plane_via
                                  : Via::kNowhere;
    Hop* h = via == Via::kPrev ? &a : via == Via::kNext ? &b : nullptr;
    if (h != nullptr) (observes(f) ? h->plane_uses : h->uses) += 1;
  }
  Share(a, config.sparsify_plane_share);
  Share(b, config.sparsify_plane_share);
  // 2. Carry every factor that is not a chain hop (loops) from v to a neighbour t, as
  //    partner k -> t. Each is removed before its replacement is added, so the factor store
  //    always has room. The replacement touches neither v nor a factor still to be visited.
  for (std::size_t i = 0; i < factor_high_water; ++i) {
    const FactorRecord& f = factors[i];
    if (!touches(f)) continue;
    const std::uint32_t k = f.a == v ? f.b : f.a;
    const RelativePoseKind kind = f.relative;
    const Via via = Route(k, p, n, a, b);
    Eigen::Isometry3d T;
    Matrix6d information, covariance;
    RelativeMeasurement(f, T, information);
    const bool from_victim = f.a == v;
    RemoveFactor(static_cast<std::int32_t>(i));
    if (via == Via::kNowhere || !Invert(information, covariance)) {
      ++stats.sparsify_dropped;
      continue;
    }
    // As k -> v: the inverse of T_v_k has covariance Ad(T) Sigma Ad(T)^T.
    Eigen::Isometry3d Z_kv = T;
    if (from_victim) {
      const Matrix6d Ad = Adjoint(T);
      covariance = (Ad * covariance * Ad.transpose()).eval();
      Z_kv = T.inverse();
    }
    Eigen::Isometry3d Z_kt;
    Matrix6d sigma_kt;
    std::uint32_t t = 0;
    if (via == Via::kNext) {  // Z_kn = Z_kv B: Ad(B^-1) Sigma_kv Ad(B^-1)^T + s_b Sigma_b
      const Matrix6d Ad = Adjoint(b.Z.inverse());
      Z_kt = Z_kv * b.Z;
      sigma_kt = Ad * covariance * Ad.transpose() + b.chain_scale * b.covariance;
      t = n;
    } else {  // Z_kp = Z_kv A^-1: Ad(A) (Sigma_kv + s_a Sigma_a) Ad(A)^T
      const Matrix6d Ad = Adjoint(a.Z);
      Z_kt = Z_kv * a.Z.inverse();
      sigma_kt = Ad * (covariance + a.chain_scale * a.covariance) * Ad.transpose();
      t = p;
    }
    Matrix6d information_kt;
    bool fused = false;
    if (Invert(sigma_kt, information_kt) &&
        AddOrFuseRelative(k, t, Z_kt, information_kt, kind, keep_factors, fused)) {
      ++stats.sparsify_carried;
      if (fused) ++stats.sparsify_merged;
    } else {
      ++stats.sparsify_dropped;
    }
  }
  // 3. Carry every plane observation on v to the neighbour its hop leads to, as t would have
  //    made it: through A to p (T_p_v = A), or through B to n (T_n_v = B^-1, whose right
  //    perturbation has covariance Ad(B) Sigma_b Ad(B)^T).
  if (plane_via != Via::kNowhere) {
    const bool next = plane_via == Via::kNext;
    const std::uint32_t t = next ? n : p;
    const Eigen::Isometry3d T_t_v = next ? b.Z.inverse() : a.Z;
    Matrix6d hop_covariance = next ? b.plane_scale * b.covariance : a.plane_scale * a.covariance;
    if (next) hop_covariance = (Adjoint(b.Z) * hop_covariance * Adjoint(b.Z).transpose()).eval();
    for (std::size_t i = 0; i < factor_high_water; ++i) {
      if (!observes(factors[i])) continue;  // a carried one is on t, never on v
      bool fused = false;
      if (CarryPlaneObservation(static_cast<std::int32_t>(i), t, T_t_v, hop_covariance, fused)) {
        ++stats.sparsify_planes_carried;
        if (fused) ++stats.sparsify_planes_fused;
      } else {
        ++stats.sparsify_planes_dropped;
      }
    }
  }
  // 4. Detach: forget the chain hops and the plane observations left on v (their measurements
  //    are in the hops, or go with v), then let Ceres drop their residuals with v's parameters.
  for (std::size_t i = 0; i < factor_high_water; ++i) {
    const FactorRecord& f = factors[i];
    if (!f.active) continue;
    if ((f.kind == FactorKind::kRelative && (f.a == v || f.b == v)) ||
        (f.kind == FactorKind::kPlane && f.a == v)) {
      if (f.kind == FactorKind::kPlane) ++stats.sparsify_planes_dropped;
      DropFactor(static_cast<std::int32_t>(i));
    }
  }
  KeyframeNode& node = keyframes[v];
  RemoveBlock(node.q);
  RemoveBlock(node.t);
  node.active = false;
  node.loop_factors = 0;
  node.prev = node.next = kNone;  // no longer in the time chain
  keyframes[p].next = static_cast<std::int32_t>(n);
  keyframes[n].prev = static_cast<std::int32_t>(p);
  keyframes[n].information_from_prev.setZero();
  free_keyframe_slots.push_back(static_cast<std::int32_t>(v));  // reserved at Init: no allocation
  --active_keyframes;
  if (had_loops) ++stats.sparsified_with_loops;
  // 5. Join the neighbours: Z = A B, Sigma = Ad(B^-1) s_a Sigma_a Ad(B^-1)^T + s_b Sigma_b
  //    (s: each hop's chain_scale).
  //    Without a measurement on one side the chain was already cut there: nothing to join.
  if (compose) {
    const Matrix6d Ad = Adjoint(b.Z.inverse());
    const Matrix6d sigma = Ad * (a.chain_scale * a.covariance) * Ad.transpose() + b.chain_scale * b.covariance;
    Matrix6d information;
    if (!Invert(sigma, information) ||
        !AddRelative(p, n, a.Z * b.Z, information, RelativePoseKind::kSparsified)) {
      ++stats.sparsify_dropped;
    }
  }
}

Status SGraph::RemoveKeyframe(std::uint32_t id, std::span<const std::uint32_t> keep_factors) {
  Impl& m = *impl_;
  if (!m.ValidKeyframe(id)) return Error{Errc::kNotFound, "no such keyframe"};
  if (static_cast<std::int32_t>(id) == m.origin)
    return Error{Errc::kInvalidArgument, "the origin holds the gauge: never removed"};
  // The local window: the newest keyframes, which the local solve moves (and the newest has no
  // successor to join to).
  const std::int32_t window_start = m.WindowStart();
  for (std::int32_t k = m.newest; k != kNone; k = m.keyframes[static_cast<std::size_t>(k)].prev) {
    if (static_cast<std::uint32_t>(k) == id)
      return Error{Errc::kInvalidArgument, "a keyframe in the local window is not removed"};
    if (k == window_start) break;
  }
  // A carried loop is another factor (another id, or fused): a loop still to be judged by its
  // id must keep its keyframe.
  for (const std::uint32_t f : keep_factors) {
    if (f < m.factor_high_water && m.factors[f].active && m.factors[f].kind == FactorKind::kRelative &&
        (m.factors[f].a == id || m.factors[f].b == id))
      return Error{Errc::kInvalidArgument, "a factor the caller keeps ends at the keyframe"};
  }
  // Sparsification at a full store takes what it must, losing a loop or cutting the chain if
  // nothing better is left; a removal on request never does.
  if (!m.RemovalLosesNothing(id))
    return Error{Errc::kInvalidArgument, "removing the keyframe would lose a constraint"};
  ++m.stats.revision;  // every call that may change the graph
  m.RemoveKeyframe(id, keep_factors);
  ++m.stats.removed_keyframes;
  return Ok();
}

}  // namespace msgraphs::core
