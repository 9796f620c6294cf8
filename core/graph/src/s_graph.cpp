// SPDX-License-Identifier: MIT
// The S-Graph's public API; its state and shared helpers are in s_graph_impl.hpp, the solves
// in s_graph_solve.cpp and sparsification in s_graph_sparsify.cpp.
#include "msgraphs/core/graph/s_graph.hpp"

#include <ceres/ceres.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <vector>

#include "msgraphs/base/assert.hpp"
#include "msgraphs/core/geometry/se3.hpp"
#include "msgraphs/core/graph/distilled_graph.hpp"
#include "msgraphs/core/graph/s_graph_solve_job.hpp"
#include "s_graph_covariance.hpp"
#include "s_graph_factors.hpp"
#include "s_graph_impl.hpp"

namespace msgraphs::core {

Status SGraphConfig::Validate() const {
  if (max_keyframes < 8 || max_planes < 1 || max_rooms < 1 || max_factors < 16) {
    return Error{Errc::kInvalidConfig,
                 "s-graph capacities too small (keyframes >= 8, factors >= 16)"};
  }
  if (!(huber_relative_pose > 0) || !(huber_loop_closure > 0) || !(huber_plane > 0) ||
      !(huber_room > 0)) {
    return Error{Errc::kInvalidConfig, "s-graph Huber thresholds must be positive"};
  }
  if (!(room_sigma_m > 0) || !(wall_wall_sigma > 0) || !(floor_room_sigma_m > 0)) {
    return Error{Errc::kInvalidConfig, "s-graph sigmas must be positive"};
  }
  if (local_window_keyframes < 2 || local_window_keyframes >= max_keyframes) {
    return Error{Errc::kInvalidConfig, "s-graph local window must be >= 2 and below max_keyframes"};
  }
  if (!(sparsify_plane_share >= 0 && sparsify_plane_share < 1)) {
    return Error{Errc::kInvalidConfig, "s-graph sparsify_plane_share must be in [0, 1)"};
  }
  if (local_max_iterations < 1 || full_max_iterations < 1 || !(local_max_seconds > 0) ||
      !(full_max_seconds > 0)) {
    return Error{Errc::kInvalidConfig, "s-graph solve limits must be positive"};
  }
  return Ok();
}

SGraph::SGraph() : impl_(std::make_unique<Impl>()) {}
SGraph::~SGraph() = default;

Status SGraph::Init(const SGraphConfig& config) {
  if (auto s = config.Validate(); !s) return s;
  Impl& m = *impl_;
  if (m.OldestBorrower() != Impl::kNoBorrower)  // it would free the costs a job evaluates
    return Error{Errc::kWouldBlock, "a background solve job borrows from this graph"};
  m.full_job_pending = false;  // a full solve destroyed unfinished gave its slot back
  m.prior_pull = false;
  m.config = config;
  ceres::Problem::Options options;
  // The graph owns the costs (RetireCost): a background solve may still be evaluating one the
  // graph removes.
  options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  options.enable_fast_removal = true;  // sparsification and room updates remove blocks
  m.DeleteCosts();  // a second Init (no job borrows them: refused above)
  m.problem = std::make_unique<ceres::Problem>(options);
  m.huber_relative = std::make_unique<ceres::HuberLoss>(config.huber_relative_pose);
  m.huber_loop = std::make_unique<ceres::HuberLoss>(config.huber_loop_closure);
  m.huber_plane = std::make_unique<ceres::HuberLoss>(config.huber_plane);
  m.huber_room = std::make_unique<ceres::HuberLoss>(config.huber_room);
  // One spare slot: AddKeyframe sparsifies after the new keyframe exists.
  m.keyframes.assign(config.max_keyframes + 1, KeyframeNode{});
  m.free_keyframe_slots.clear();
  m.free_keyframe_slots.reserve(config.max_keyframes + 1);
  m.keyframe_high_water = 0;
  m.newest = m.origin = kNone;
  m.active_keyframes = 0;
  m.planes.assign(config.max_planes, PlaneNode{});
  m.plane_count = 0;
  m.rooms.assign(config.max_rooms, RoomNode{});
  m.room_count = 0;
  m.floor_active = false;
  m.factors.assign(config.max_factors, FactorRecord{});
  m.free_factor_slots.clear();
  m.free_factor_slots.reserve(config.max_factors);
  m.factor_high_water = m.active_factors = 0;
  m.residual_index.Init(config.max_factors);
  m.marginals_now.reset();  // sized for the old config
  m.scratch_blocks.reserve(16);  // a factor's blocks (a room's: 9): Save allocates nothing
  m.retired_costs.reserve(config.max_factors);
  m.plane_only_factors.clear();
  m.plane_only_factors.reserve(config.max_factors);
  m.held_epoch = 1;
  m.scratch_costs.reserve(1024);  // the residual blocks on one node (RemoveBlock)
  m.snapshot.assign(
      (config.max_keyframes + 1) * 7 + config.max_planes * 4 + config.max_rooms * 2 + 2, 0.0);
  // The revision goes on from the graph's before: a reader that saw an earlier graph of this
  // object never takes the new one for it.
  const std::uint64_t revision = m.stats.revision;
  m.stats = SGraphStats{};
  m.stats.revision = revision + 1;
  m.stats.store_bytes =
      m.keyframes.size() * sizeof(KeyframeNode) + m.planes.size() * sizeof(PlaneNode) +
      m.rooms.size() * sizeof(RoomNode) + m.factors.size() * sizeof(FactorRecord) +
      m.snapshot.size() * sizeof(double) +
      (m.free_keyframe_slots.capacity() + m.free_factor_slots.capacity() +
       m.plane_only_factors.capacity()) *
          sizeof(std::int32_t) +
      m.residual_index.bytes();
  return Ok();
}

void SGraph::Impl::CompactPlaneOnlyFactors() {
  const auto gone = [this](std::int32_t slot) {
    const FactorRecord& f = factors[static_cast<std::size_t>(slot)];
    return !f.active || (f.kind != FactorKind::kWallWall && f.kind != FactorKind::kPlanePrior);
  };
  plane_only_factors.erase(
      std::remove_if(plane_only_factors.begin(), plane_only_factors.end(), gone),
      plane_only_factors.end());
  std::sort(plane_only_factors.begin(), plane_only_factors.end());
  plane_only_factors.erase(std::unique(plane_only_factors.begin(), plane_only_factors.end()),
                           plane_only_factors.end());
}

Expected<std::uint32_t> SGraph::AddKeyframe(double stamp_s,
                                            const Eigen::Isometry3d& T_map_keyframe) {
  Impl& m = *impl_;
  ++m.stats.revision;  // every call that may change the graph
  if (!m.problem) return Error{Errc::kInvalidArgument, "s-graph not initialised"};
  if (!std::isfinite(stamp_s) || !IsValidRigidTransform(T_map_keyframe, 1e-6)) {
    ++m.stats.rejected_pose;
    return Error{Errc::kInvalidArgument, "keyframe pose or stamp is not finite / not rigid"};
  }
  if (m.newest != kNone && !(stamp_s > m.keyframes[static_cast<std::size_t>(m.newest)].stamp_s)) {
    ++m.stats.rejected_stamp;
    return Error{Errc::kOutOfOrder, "keyframe stamp not after the previous keyframe's"};
  }
  // The store holds max_keyframes + 1: the new keyframe enters before one is sparsified, so
  // that the local window includes it. Every slot is taken only if the last sparsification
  // found no keyframe to remove (validation rules that out): try once more, else refuse.
  if (m.free_keyframe_slots.empty() && m.keyframe_high_water >= m.keyframes.size() &&
      !m.Sparsify()) {
    ++m.stats.rejected_keyframes;
    return Error{Errc::kCapacityExceeded, "s-graph keyframe store full and nothing to sparsify"};
  }
  std::int32_t slot = kNone;
  if (!m.free_keyframe_slots.empty()) {
    slot = m.free_keyframe_slots.back();
    m.free_keyframe_slots.pop_back();
  } else {
    slot = static_cast<std::int32_t>(m.keyframe_high_water++);
  }
  MSGRAPHS_ASSERT(slot >= 0 && static_cast<std::size_t>(slot) < m.keyframes.size(),
                  "s-graph keyframe slot beyond the store");
  KeyframeNode& k = m.keyframes[static_cast<std::size_t>(slot)];
  k = KeyframeNode{};
  m.SetPose(static_cast<std::uint32_t>(slot), T_map_keyframe);
  k.stamp_s = stamp_s;
  k.prev = m.newest;
  k.active = true;
  if (m.newest != kNone) m.keyframes[static_cast<std::size_t>(m.newest)].next = slot;
  m.newest = slot;
  m.problem->AddParameterBlock(k.q, 4, &m.quaternion_manifold);
  m.problem->AddParameterBlock(k.t, 3);
  if (m.origin == kNone) {
    // The gauge: the first keyframe is the map's origin and never moves.
    m.origin = slot;
    m.problem->SetParameterBlockConstant(k.q);
    m.problem->SetParameterBlockConstant(k.t);
  }
  ++m.active_keyframes;
  // A failed sparsification leaves the spare slot taken; the next AddKeyframe tries again and
  // refuses (counted) if it fails again.
  if (m.active_keyframes > m.config.max_keyframes && !m.Sparsify()) ++m.stats.sparsify_failed;
  m.stats.keyframes_peak = std::max(m.stats.keyframes_peak, m.active_keyframes);
  return static_cast<std::uint32_t>(slot);
}

Expected<std::uint32_t> SGraph::AddRelativePose(std::uint32_t from,
                                                std::uint32_t to,
                                                const Eigen::Isometry3d& T_from_to,
                                                const Matrix6d& information,
                                                RelativePoseKind kind) {
  ++impl_->stats.revision;  // every call that may change the graph
  return impl_->AddRelative(from, to, T_from_to, information, kind);
}

Expected<double> SGraph::FactorChi2(std::uint32_t factor) const {
  const Impl& m = *impl_;
  if (factor >= m.factor_high_water || !m.factors[factor].active)
    return Error{Errc::kNotFound, "no such factor"};
  double cost = 0;
  if (!m.problem->EvaluateResidualBlock(m.factors[factor].id, false, &cost, nullptr, nullptr)) {
    return Error{Errc::kDegenerate, "factor could not be evaluated"};
  }
  return 2.0 * cost;  // Ceres' cost is half the squared norm
}

bool SGraph::IsPlanePriorFactor(std::uint32_t factor) const {
  const Impl& m = *impl_;
  return factor < m.factor_high_water && m.factors[factor].active &&
         m.factors[factor].kind == FactorKind::kPlanePrior;
}

bool SGraph::IsLoopFactor(std::uint32_t factor) const {
  const Impl& m = *impl_;
  if (factor >= m.factor_high_water || !m.factors[factor].active) return false;
  const FactorRecord& f = m.factors[factor];
  return f.kind == FactorKind::kRelative && f.relative == RelativePoseKind::kLoopClosure;
}

Status SGraph::RemoveFactor(std::uint32_t factor) {
  Impl& m = *impl_;
  ++m.stats.revision;  // every call that may change the graph
  if (factor >= m.factor_high_water || !m.factors[factor].active)
    return Error{Errc::kNotFound, "no such factor"};
  const FactorKind kind = m.factors[factor].kind;
  if (kind == FactorKind::kRoom || kind == FactorKind::kFloorRoom) {
    return Error{Errc::kInvalidArgument,
                 "room factors go with their room (UpdateRoom / RemoveRoom)"};
  }
  m.RemoveFactor(static_cast<std::int32_t>(factor));
  return Ok();
}

Expected<std::uint32_t> SGraph::AddPlane(const Eigen::Vector3d& normal_map,
                                         double d_map,
                                         PlaneClass plane_class) {
  Impl& m = *impl_;
  ++m.stats.revision;  // every call that may change the graph
  if (!normal_map.allFinite() || !std::isfinite(d_map) || normal_map.norm() < 1e-6) {
    ++m.stats.rejected_pose;
    return Error{Errc::kInvalidArgument, "plane is not finite"};
  }
  if (m.plane_count >= m.planes.size()) {
    ++m.stats.rejected_capacity;
    return Error{Errc::kCapacityExceeded, "s-graph plane store full"};
  }
  PlaneNode& p = m.planes[m.plane_count];
  p = PlaneNode{};
  const double norm = normal_map.norm();
  for (int i = 0; i < 3; ++i) p.n[i] = normal_map[i] / norm;
  p.d[0] = d_map / norm;
  p.info.plane_class = plane_class;
  p.info.active = true;
  // A fixed basis of the plane for its information: horizontal u for walls (along the wall).
  WallBasis(Eigen::Vector3d(p.n[0], p.n[1], p.n[2]), p.info.basis_u, p.info.basis_v);
  return static_cast<std::uint32_t>(m.plane_count++);
}

Status SGraph::AddPlaneObservation(std::uint32_t keyframe,
                                   std::uint32_t plane,
                                   const PlaneMeasurement& z,
                                   double behind_margin_m) {
  Impl& m = *impl_;
  ++m.stats.revision;  // every call that may change the graph
  if (!m.ValidKeyframe(keyframe) || !m.ValidPlane(plane)) {
    ++m.stats.rejected_missing_node;
    return Error{Errc::kNotFound, "plane observation of a missing keyframe or plane"};
  }
  if (!z.normal.allFinite() || !std::isfinite(z.d) || !z.basis_u.allFinite() ||
      !z.basis_v.allFinite()) {
    ++m.stats.rejected_pose;
    return Error{Errc::kInvalidArgument, "plane measurement is not finite"};
  }
  Eigen::Matrix3d information;
  Eigen::Matrix3d sqrt_information;
  {
    if (!z.covariance.allFinite() || !z.covariance.isApprox(z.covariance.transpose(), 1e-6)) {
      ++m.stats.rejected_information;
      return Error{Errc::kInvalidArgument, "plane covariance not symmetric"};
    }
    Eigen::LLT<Eigen::Matrix3d> llt(z.covariance);
    if (llt.info() != Eigen::Success) {
      ++m.stats.rejected_information;
      return Error{Errc::kInvalidArgument, "plane covariance not positive definite"};
    }
    information = z.covariance.inverse();
    information = 0.5 * (information + information.transpose()).eval();
    Eigen::LLT<Eigen::Matrix3d> info_llt(information);
    if (info_llt.info() != Eigen::Success) {
      ++m.stats.rejected_information;
      return Error{Errc::kInvalidArgument, "plane information not positive definite"};
    }
    sqrt_information = info_llt.matrixU();
  }
  PlaneNode& p = m.planes[plane];
  const Eigen::Isometry3d T = m.Pose(keyframe);
  const Eigen::Vector3d n_map(p.n[0], p.n[1], p.n[2]);
  // Seen from behind: the keyframe stands behind the plane, or the measured normal points the
  // other way. Either means the other face of the wall (or a wrong association).
  const double signed_distance = n_map.dot(T.translation()) + p.d[0];
  const Eigen::Vector3d n_predicted = T.linear().transpose() * n_map;
  if (signed_distance < -behind_margin_m || n_predicted.dot(z.normal.normalized()) < 0.5) {
    ++m.stats.rejected_behind;
    return Error{Errc::kInvalidArgument, "plane seen from behind"};
  }
  if (auto slot = m.AddPlaneFactor(keyframe, plane, {z.basis_u, z.basis_v, z.d, sqrt_information}); !slot)
    return slot.error();
  // Information of this observation about the map plane: the Jacobian of the measurement
  // coordinates (u_m.n_k, v_m.n_k, d_k) with respect to the map plane's (alpha, beta, delta_d),
  // n_k = R^T n and d_k = d + n.t, at the keyframe's current estimate.
  Eigen::Matrix3d J = Eigen::Matrix3d::Zero();
  const Eigen::Vector3d ru = T.linear().transpose() * p.info.basis_u,
                        rv = T.linear().transpose() * p.info.basis_v;
  J << z.basis_u.dot(ru), z.basis_u.dot(rv), 0, z.basis_v.dot(ru), z.basis_v.dot(rv), 0,
      p.info.basis_u.dot(T.translation()), p.info.basis_v.dot(T.translation()), 1;
  p.info.information += J.transpose() * information * J;
  ++p.info.observations;
  // The newest observer (the local solve frees a plane its window sees): an observation by an
  // older keyframe does not move it back.
  p.info.last_observed_s = std::max(p.info.last_observed_s, m.keyframes[keyframe].stamp_s);
  return Ok();
}

Expected<std::uint32_t> SGraph::AddRoom(const MapRoom& room) {
  Impl& m = *impl_;
  ++m.stats.revision;  // every call that may change the graph
  if (m.room_count >= m.rooms.size()) {
    ++m.stats.rejected_capacity;
    return Error{Errc::kCapacityExceeded, "s-graph room store full"};
  }
  const auto id = static_cast<std::uint32_t>(m.room_count);
  RoomNode& r = m.rooms[id];
  r = RoomNode{};
  r.c[0] = room.centre.x();
  r.c[1] = room.centre.y();
  r.info = room;
  r.info.active = true;
  ++m.room_count;
  if (auto s = UpdateRoom(id, room); !s) {
    --m.room_count;
    r.info.active = false;
    return s.error();
  }
  return id;
}

Status SGraph::UpdateRoom(std::uint32_t id, const MapRoom& updated) {
  Impl& m = *impl_;
  ++m.stats.revision;  // every call that may change the graph
  if (!m.ValidRoom(id)) {
    ++m.stats.rejected_missing_node;
    return Error{Errc::kNotFound, "no such room"};
  }
  const int wall_count = updated.shape == RoomShape::kFourWall ? 4 : 2;
  for (int i = 0; i < wall_count; ++i) {
    const std::int32_t w = updated.walls[static_cast<std::size_t>(i)];
    if (w < 0 || !m.ValidPlane(static_cast<std::uint32_t>(w)) ||
        !m.planes[static_cast<std::size_t>(w)].in_problem) {
      ++m.stats.rejected_missing_node;
      return Error{Errc::kNotFound, "room wall is not an observed plane"};
    }
  }
  if (!updated.centre.allFinite() || !updated.corridor_anchor.allFinite()) {
    ++m.stats.rejected_pose;
    return Error{Errc::kInvalidArgument, "room centre not finite"};
  }
  RoomNode& r = m.rooms[id];
  if (r.factor != kNone) {
    m.RemoveFactor(r.factor);
    r.factor = kNone;
  }
  auto slot = m.NewFactor(FactorKind::kRoom, id, 0);
  if (!slot) return slot.error();
  if (!r.in_problem) {
    m.problem->AddParameterBlock(r.c, 2);
    r.in_problem = true;
  }
  const bool moved = (Eigen::Vector2d(r.c[0], r.c[1]) - updated.centre).norm() > 0.5;
  if (moved || r.info.shape != updated.shape) {
    r.c[0] = updated.centre.x();
    r.c[1] = updated.centre.y();
  }
  const double inv_sigma = 1.0 / m.config.room_sigma_m;
  auto W = [&](int i) -> PlaneNode& {
    return m.planes[static_cast<std::size_t>(updated.walls[static_cast<std::size_t>(i)])];
  };
  ceres::ResidualBlockId block = nullptr;
  if (updated.shape == RoomShape::kFourWall) {
    auto* cost = new sgraph::RoomCost(new sgraph::RoomResidual{inv_sigma});
    block = m.problem->AddResidualBlock(
        cost, m.huber_room.get(),
        {r.c, W(0).n, W(0).d, W(1).n, W(1).d, W(2).n, W(2).d, W(3).n, W(3).d});
  } else {
    auto* cost = new sgraph::CorridorCost(
        new sgraph::CorridorResidual{updated.corridor_anchor, inv_sigma});
    block =
        m.problem->AddResidualBlock(cost, m.huber_room.get(), r.c, W(0).n, W(0).d, W(1).n, W(1).d);
  }
  m.Bind(*slot, block);
  ++m.stats.room_factors;
  r.factor = *slot;
  const bool active = r.info.active;
  r.info = updated;
  r.info.active = active;
  return Ok();
}

Status SGraph::RemoveRoom(std::uint32_t id) {
  Impl& m = *impl_;
  ++m.stats.revision;  // every call that may change the graph
  if (!m.ValidRoom(id)) return Error{Errc::kNotFound, "no such room"};
  RoomNode& r = m.rooms[id];
  if (r.factor != kNone) m.RemoveFactor(r.factor);
  if (r.floor_factor != kNone) m.RemoveFactor(r.floor_factor);
  r.factor = r.floor_factor = kNone;
  if (r.in_problem) m.RemoveBlock(r.c);
  r.in_problem = false;
  r.info.active = false;
  return Ok();
}

Status SGraph::AddWallWall(std::uint32_t a, std::uint32_t b) {
  Impl& m = *impl_;
  ++m.stats.revision;  // every call that may change the graph
  if (a == b || !m.ValidPlane(a) || !m.ValidPlane(b) || !m.planes[a].in_problem ||
      !m.planes[b].in_problem) {
    ++m.stats.rejected_missing_node;
    return Error{Errc::kNotFound, "wall-wall factor between missing planes"};
  }
  const Eigen::Vector3d na(m.planes[a].n[0], m.planes[a].n[1], m.planes[a].n[2]);
  const Eigen::Vector3d nb(m.planes[b].n[0], m.planes[b].n[1], m.planes[b].n[2]);
  if (na.dot(nb) < 0.5) {
    ++m.stats.rejected_behind;
    return Error{Errc::kInvalidArgument, "wall-wall factor between opposite faces"};
  }
  auto slot = m.NewFactor(FactorKind::kWallWall, a, b);
  if (!slot) return slot.error();
  auto* cost = new sgraph::WallWallCost(
      new sgraph::WallWallResidual{1.0 / m.config.wall_wall_sigma});
  m.Bind(*slot, m.problem->AddResidualBlock(
      cost, m.huber_plane.get(), m.planes[a].n, m.planes[a].d, m.planes[b].n, m.planes[b].d));
  ++m.stats.wall_wall_factors;
  return Ok();
}

Expected<std::uint32_t> SGraph::AddPlanePrior(const PlanePrior& prior) {
  Impl& m = *impl_;
  ++m.stats.revision;  // every call that may change the graph
  if (!m.ValidPlane(prior.plane) || !m.planes[prior.plane].in_problem) {
    ++m.stats.rejected_missing_node;
    return Error{Errc::kNotFound, "plane prior on a missing plane"};
  }
  if (!prior.normal.allFinite() || std::fabs(prior.normal.norm() - 1.0) > 1e-3 ||
      !std::isfinite(prior.d)) {
    ++m.stats.rejected_pose;
    return Error{Errc::kInvalidArgument, "plane prior not finite or not unit"};
  }
  Eigen::LLT<Eigen::Matrix3d> llt(prior.covariance);
  if (!prior.covariance.allFinite() || llt.info() != Eigen::Success) {
    ++m.stats.rejected_information;
    return Error{Errc::kInvalidArgument, "plane prior covariance not positive definite"};
  }
  PlaneNode& p = m.planes[prior.plane];
  const Eigen::Vector3d n(p.n[0], p.n[1], p.n[2]);
  if (n.dot(prior.normal) < 0.5) {
    ++m.stats.rejected_behind;
    return Error{Errc::kInvalidArgument, "plane prior facing the other way"};
  }
  Eigen::Matrix3d information = prior.covariance.inverse();
  information = 0.5 * (information + information.transpose()).eval();
  Eigen::LLT<Eigen::Matrix3d> info_llt(information);
  if (info_llt.info() != Eigen::Success) {
    ++m.stats.rejected_information;
    return Error{Errc::kInvalidArgument, "plane prior information not positive definite"};
  }
  auto slot = m.NewFactor(FactorKind::kPlanePrior, prior.plane, 0);
  if (!slot) return slot.error();
  Eigen::Vector3d u, v;
  WallBasis(prior.normal, u, v);
  auto* cost = new sgraph::PlanePriorCost(
      new sgraph::PlanePriorResidual{u, v, prior.d, Eigen::Matrix3d(info_llt.matrixU())});
  m.Bind(*slot, m.problem->AddResidualBlock(cost, m.huber_plane.get(), p.n, p.d));
  ++m.stats.plane_prior_factors;
  m.prior_pull = true;
  ++m.prior_adds;
  return static_cast<std::uint32_t>(*slot);
}

Status SGraph::SetFloor(const Eigen::Vector2d& centre) {
  Impl& m = *impl_;
  ++m.stats.revision;  // every call that may change the graph
  if (!centre.allFinite()) {
    ++m.stats.rejected_pose;
    return Error{Errc::kInvalidArgument, "floor centre not finite"};
  }
  m.floor_c[0] = centre.x();
  m.floor_c[1] = centre.y();
  if (!m.floor_active) {
    m.problem->AddParameterBlock(m.floor_c, 2);
    m.floor_active = true;
  }
  return Ok();
}

Status SGraph::AddFloorRoom(std::uint32_t room) {
  Impl& m = *impl_;
  ++m.stats.revision;  // every call that may change the graph
  if (!m.floor_active || !m.ValidRoom(room)) {
    ++m.stats.rejected_missing_node;
    return Error{Errc::kNotFound, "floor-room factor without floor or room"};
  }
  RoomNode& r = m.rooms[room];
  if (r.floor_factor != kNone) m.RemoveFactor(r.floor_factor);
  r.floor_factor = kNone;
  auto slot = m.NewFactor(FactorKind::kFloorRoom, room, 0);
  if (!slot) return slot.error();
  const Eigen::Vector2d offset(m.floor_c[0] - r.c[0], m.floor_c[1] - r.c[1]);
  auto* cost = new sgraph::FloorRoomCost(
      new sgraph::FloorRoomResidual{offset, 1.0 / m.config.floor_room_sigma_m});
  m.Bind(*slot, m.problem->AddResidualBlock(cost, nullptr, m.floor_c, r.c));
  ++m.stats.floor_factors;
  r.floor_factor = *slot;
  return Ok();
}

std::size_t SGraph::keyframe_slots() const { return impl_->keyframe_high_water; }
std::uint32_t SGraph::FirstKeyframe() const {
  const std::int32_t k = impl_->origin;
  return k == kNone ? kNoKeyframe : static_cast<std::uint32_t>(k);
}
std::uint32_t SGraph::NextKeyframe(std::uint32_t id) const {
  if (!impl_->ValidKeyframe(id)) return kNoKeyframe;
  const std::int32_t k = impl_->keyframes[id].next;
  return k == kNone ? kNoKeyframe : static_cast<std::uint32_t>(k);
}
bool SGraph::keyframe_active(std::uint32_t id) const { return impl_->ValidKeyframe(id); }
Eigen::Isometry3d SGraph::keyframe_pose(std::uint32_t id) const {
  return id < impl_->keyframe_high_water ? impl_->Pose(id) : Eigen::Isometry3d::Identity();
}
double SGraph::keyframe_stamp(std::uint32_t id) const {
  return id < impl_->keyframe_high_water ? impl_->keyframes[id].stamp_s : 0.0;
}
std::size_t SGraph::plane_slots() const { return impl_->plane_count; }
MapPlane SGraph::plane(std::uint32_t id) const {
  if (id >= impl_->plane_count) return MapPlane{};
  const PlaneNode& p = impl_->planes[id];
  MapPlane out = p.info;
  out.normal = Eigen::Vector3d(p.n[0], p.n[1], p.n[2]).normalized();
  out.d = p.d[0];
  return out;
}
Status SGraph::PlaneMarginals(std::span<const std::uint32_t> ids,
                              std::span<Eigen::Matrix3d> covariances) const {
  Impl& m = *impl_;
  if (covariances.size() < ids.size())
    return Error{Errc::kCapacityExceeded, "plane marginals: output shorter than the plane list"};
  // Ceres recovers the marginals from one factorisation of the whole problem; it allocates,
  // which is why this runs at the distillation cadence, not per keyframe (and the distiller
  // runs it in the background: BeginPlaneMarginals). It runs the same job here, on the spot:
  // the job holds its estimates in one buffer in slot order, and Ceres' covariance orders
  // blocks by address, so the result never depends on where the heap put the graph's stores.
  if (!m.marginals_now) {
    auto job = std::make_unique<SGraphSolveJob>();  // once per Init
    if (auto s = job->Init(m.config); !s) return s;
    m.marginals_now = std::move(job);
  }
  SGraphSolveJob& job = *m.marginals_now;
  if (auto s = BeginPlaneMarginals(job, ids, PlaneEvidence::kAll); !s) return s;
  job.Complete();
  const std::span<const Eigen::Matrix3d> result = job.plane_marginals();
  const bool ok = result.size() == ids.size();
  if (ok) std::copy(result.begin(), result.end(), covariances.begin());
  static_cast<void>(job.Release());
  if (!ok) return Error{Errc::kDegenerate, "plane marginals: the problem is rank deficient"};
  return Ok();
}

std::size_t SGraph::room_slots() const { return impl_->room_count; }
MapRoom SGraph::room(std::uint32_t id) const {
  if (id >= impl_->room_count) return MapRoom{};
  MapRoom out = impl_->rooms[id].info;
  out.centre = Eigen::Vector2d(impl_->rooms[id].c[0], impl_->rooms[id].c[1]);
  return out;
}
bool SGraph::has_floor() const { return impl_->floor_active; }
bool SGraph::estimates_hold_priors() const { return impl_->prior_pull; }
Eigen::Vector2d SGraph::floor_centre() const { return {impl_->floor_c[0], impl_->floor_c[1]}; }

std::size_t SGraph::RecentKeyframes(std::span<std::uint32_t> out) const {
  const Impl& m = *impl_;
  std::size_t count = 0;
  std::int32_t k = m.newest;
  while (k != kNone && count < out.size()) {
    ++count;
    k = m.keyframes[static_cast<std::size_t>(k)].prev;
  }
  // Fill oldest first.
  k = m.newest;
  for (std::size_t i = count; i-- > 0;) {
    out[i] = static_cast<std::uint32_t>(k);
    k = m.keyframes[static_cast<std::size_t>(k)].prev;
  }
  return count;
}

SGraphStats SGraph::stats() const {
  SGraphStats s = impl_->stats;
  s.keyframes = impl_->active_keyframes;
  s.planes = impl_->plane_count;
  s.rooms = 0;
  for (std::size_t i = 0; i < impl_->room_count; ++i)
    s.rooms += impl_->rooms[i].info.active ? 1u : 0u;
  s.floors = impl_->floor_active ? 1u : 0u;
  s.retired_costs = impl_->retired_costs.size();
  s.factors = impl_->active_factors;
  return s;
}

const SGraphConfig& SGraph::config() const { return impl_->config; }

}  // namespace msgraphs::core
