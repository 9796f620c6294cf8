// SPDX-License-Identifier: MIT
// The full solve in the background (s_graph_solve_job.hpp, docs/s-graph.md).
//
// The job holds two copies of every estimate: `begin` as the graph had it at BeginFullSolve,
// and `solved`, which Run optimises in place. ApplyFullSolve gives every keyframe and plane the
// job held its solution: the local solves since may have pulled the newest of them towards a
// loop closure the solution holds in full already, so adding their change would count that
// pull twice; the next local solve brings back what the observations since say. A node added
// since moves with the newest keyframe the job held (the anchor), from where the anchor is now
// to its solution: it keeps its pose relative to the keyframe it was built on. Rooms and the
// floor, which are re-centred by the room mapper between solves, get solved + (now - begin).
//
// A marginals job (BeginPlaneMarginals) takes the same copy; Run (s_graph_solve_job.cpp)
// computes the planes' covariances on it (after solving it without the plane priors, for a
// kOwn copy of a graph they pulled) and ends the job's borrowing of the graph's costs.
#include <ceres/ceres.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <type_traits>
#include <vector>

#include "msgraphs/core/graph/s_graph.hpp"
#include "msgraphs/core/graph/s_graph_solve_job.hpp"
#include "s_graph_solve_job_impl.hpp"

namespace msgraphs::core {

using sgraph::JobKind;
using sgraph::JobResidual;
using sgraph::kDone;
using sgraph::kIdle;
using sgraph::kReady;
using sgraph::Values;

Status SGraph::BeginFullSolve(SGraphSolveJob& job) {
  Impl& m = *impl_;
  if (m.full_job_pending) return Error{Errc::kWouldBlock, "a background solve is pending"};
  if (auto s = CopyIntoJob(job, PlaneEvidence::kAll); !s) return s;
  SGraphSolveJob::Impl& j = *job.impl_;
  j.kind = JobKind::kFullSolve;
  m.full_job_pending = true;
  j.state.store(kReady, std::memory_order_release);
  return Ok();
}

Status SGraph::BeginPlaneMarginals(SGraphSolveJob& job,
                                   std::span<const std::uint32_t> ids,
                                   PlaneEvidence evidence) const {
  const Impl& m = *impl_;
  SGraphSolveJob::Impl& j = *job.impl_;
  if (j.sized && ids.size() > j.marginals.size())
    return Error{Errc::kCapacityExceeded, "more planes than the job holds"};
  for (std::uint32_t id : ids) {
    if (id >= m.plane_count || !m.planes[id].in_problem)
      return Error{Errc::kNotFound, "plane marginals: plane not in the optimisation"};
    if (m.planes[id].info.live_observations == 0)  // as PlaneMarginals: no zero covariance
      return Error{Errc::kInvalidArgument, "plane marginals: the plane has no observation left"};
  }
  if (auto s = CopyIntoJob(job, evidence); !s) return s;
  j.kind = JobKind::kMarginals;
  j.marginal_ids.clear();
  j.marginal_blocks.clear();
  j.marginals_ok = false;
  for (std::uint32_t id : ids) {
    const PlaneNode& p = m.planes[id];
    j.marginal_ids.push_back(id);
    j.marginal_blocks.push_back({&j.solved.pn[3 * id], &j.solved.pd[id], p.info.basis_u,
                                 p.info.basis_v});
  }
  j.state.store(kReady, std::memory_order_release);
  return Ok();
}

Status SGraph::CopyIntoJob(SGraphSolveJob& job, PlaneEvidence evidence) const {
  Impl& m = *impl_;
  SGraphSolveJob::Impl& j = *job.impl_;
  if (!m.problem) return Error{Errc::kInvalidArgument, "s-graph not initialised"};
  if (!j.sized || j.stamp.size() < m.keyframes.size() || j.plane_in.size() < m.planes.size() ||
      j.room_in.size() < m.rooms.size()) {
    return Error{Errc::kInvalidArgument, "solve job sized for a smaller graph"};
  }
  if (j.state.load() != kIdle) return Error{Errc::kWouldBlock, "the job is pending"};
  j.config = m.config;  // the graph's solver limits
  Values& b = j.begin;
  j.keyframe_slots = m.keyframe_high_water;
  for (std::size_t k = 0; k < m.keyframe_high_water; ++k) {
    const KeyframeNode& node = m.keyframes[k];
    j.keyframe_in[k] = node.active;
    j.stamp[k] = node.stamp_s;
    std::copy(node.q, node.q + 4, &b.kq[4 * k]);
    std::copy(node.t, node.t + 3, &b.kt[3 * k]);
  }
  j.origin = m.origin;
  j.plane_count = m.plane_count;
  for (std::size_t i = 0; i < m.plane_count; ++i) {
    const PlaneNode& p = m.planes[i];
    j.plane_in[i] = p.in_problem;
    std::copy(p.n, p.n + 3, &b.pn[3 * i]);
    b.pd[i] = p.d[0];
  }
  j.room_count = m.room_count;
  for (std::size_t i = 0; i < m.room_count; ++i) {
    j.room_in[i] = m.rooms[i].in_problem;
    std::copy(m.rooms[i].c, m.rooms[i].c + 2, &b.rc[2 * i]);
  }
  j.floor_in = m.problem->HasParameterBlock(m.floor_c);
  std::copy(m.floor_c, m.floor_c + 2, b.floor);
  j.solved = b;  // same sizes: copies into the memory Init made
  // The residual blocks, their parameter blocks mapped from the graph's memory to the copy's.
  Values& x = j.solved;
  const auto slot = [](const auto& store, const double* block) -> std::size_t {
    using Node = typename std::decay_t<decltype(store)>::value_type;
    const auto* base = reinterpret_cast<const unsigned char*>(store.data());
    const auto* at = reinterpret_cast<const unsigned char*>(block);
    if (at < base || at >= base + store.size() * sizeof(Node)) return store.size();
    return static_cast<std::size_t>(at - base) / sizeof(Node);
  };
  const auto map = [&](const double* block) -> double* {
    if (const std::size_t k = slot(m.keyframes, block); k < m.keyframes.size()) {
      if (block == m.keyframes[k].q) return &x.kq[4 * k];
      if (block == m.keyframes[k].t) return &x.kt[3 * k];
    } else if (const std::size_t i = slot(m.planes, block); i < m.planes.size()) {
      if (block == m.planes[i].n) return &x.pn[3 * i];
      if (block == m.planes[i].d) return &x.pd[i];
    } else if (const std::size_t r = slot(m.rooms, block); r < m.rooms.size()) {
      if (block == m.rooms[r].c) return &x.rc[2 * r];
    } else if (block == m.floor_c) {
      return x.floor;
    }
    return nullptr;
  };
  // The residual blocks in factor-slot order (not the graph's problem's, a history of
  // additions and removals): a copy of the same records is the same problem for Ceres. A kOwn
  // copy leaves the plane priors out.
  j.priors_left_out = 0;
  j.priors_at_copy = m.stats.plane_prior_factors;
  j.prior_adds_at_copy = m.prior_adds;
  j.own_solve_usable = j.own_solve_converged = true;
  j.residuals.clear();
  j.refs.clear();
  for (std::size_t f = 0; f < m.factor_high_water; ++f) {
    const FactorRecord& rec = m.factors[f];
    if (!rec.active) continue;
    if (evidence == PlaneEvidence::kOwn && rec.kind == FactorKind::kPlanePrior) {
      ++j.priors_left_out;
      continue;
    }
    const ceres::ResidualBlockId id = rec.id;
    JobResidual r;
    r.cost = m.problem->GetCostFunctionForResidualBlock(id);
    r.loss = m.problem->GetLossFunctionForResidualBlock(id);
    r.id = id;
    r.first = static_cast<std::uint32_t>(j.refs.size());
    m.problem->GetParameterBlocksForResidualBlock(id, &m.scratch_blocks);
    for (const double* block : m.scratch_blocks) {
      double* mapped = map(block);
      if (mapped == nullptr)
        return Error{Errc::kInvalidArgument, "parameter block not in the graph"};
      j.refs.push_back(mapped);
    }
    r.count = static_cast<std::uint32_t>(m.scratch_blocks.size());
    j.residuals.push_back(r);
  }
  if (j.residuals.size() + j.priors_left_out != static_cast<std::size_t>(m.problem->NumResidualBlocks()))
    return Error{Errc::kInvalidArgument, "a residual block of the graph has no factor record"};
  j.solve_first = evidence == PlaneEvidence::kOwn && (j.priors_left_out > 0 || m.prior_pull);
  Impl::Borrower* borrower = m.TakeBorrower();
  if (borrower == nullptr)
    return Error{Errc::kWouldBlock, "too many jobs borrow from this graph"};
  j.graph = this;
  j.borrowing = &borrower->borrowing;
  m.ReleaseRetiredCosts();  // what no job borrows any more
  return Ok();
}

Expected<double> SGraph::FactorChi2(const SGraphSolveJob& job, std::uint32_t factor) const {
  const Impl& m = *impl_;
  const SGraphSolveJob::Impl& j = *job.impl_;
  if (j.graph != this || j.kind != JobKind::kFullSolve ||
      j.state.load(std::memory_order_acquire) != kDone)
    return Error{Errc::kInvalidArgument, "solve job not done on this graph"};
  if (!j.report.usable)  // a failed solve judges nothing
    return Error{Errc::kNotConverged, "the solve job's solution is not usable"};
  if (factor >= m.factor_high_water || !m.factors[factor].active)
    return Error{Errc::kNotFound, "no such factor"};
  const ceres::ResidualBlockId id = m.factors[factor].id;
  // Costs are never freed while the job borrows them, so the pair names one factor.
  const ceres::CostFunction* cost = m.problem->GetCostFunctionForResidualBlock(id);
  for (const JobResidual& r : j.residuals) {
    if (r.id != id || r.cost != cost) continue;
    std::array<double, 16> residual{};
    if (cost->num_residuals() > static_cast<int>(residual.size()))
      return Error{Errc::kInvalidArgument, "factor too large to evaluate"};
    if (!cost->Evaluate(j.refs.data() + r.first, residual.data(), nullptr))
      return Error{Errc::kDegenerate, "factor could not be evaluated"};
    double chi2 = 0;
    for (int i = 0; i < cost->num_residuals(); ++i)
      chi2 += residual[static_cast<std::size_t>(i)] * residual[static_cast<std::size_t>(i)];
    return chi2;
  }
  return Error{Errc::kNotFound, "factor not in the solve job"};
}

void SGraph::DropFullSolve(SGraphSolveJob& job) {
  Impl& m = *impl_;
  SGraphSolveJob::Impl& j = *job.impl_;
  if (j.graph != this || j.kind != JobKind::kFullSolve) return;
  if (j.state.load() != kIdle && !job.TryClaim()) job.Complete();  // a runner has it: wait
  j.state.store(kIdle, std::memory_order_release);
  j.graph = nullptr;
  m.full_job_pending = false;
  j.EndBorrowing();
  m.ReleaseRetiredCosts();
}

Expected<SGraphSolveReport> SGraph::ApplyFullSolve(SGraphSolveJob& job) {
  Impl& m = *impl_;
  SGraphSolveJob::Impl& j = *job.impl_;
  if (j.graph != this || j.kind != JobKind::kFullSolve ||
      j.state.load(std::memory_order_acquire) != kDone)
    return Error{Errc::kInvalidArgument, "solve job not done on this graph"};
  const SGraphSolveReport report = j.report;
  ++m.stats.solves;
  if (!report.converged) ++m.stats.solves_not_converged;
  if (!report.usable) {
    ++m.stats.background_unusable;
    DropFullSolve(job);
    return report;
  }
  ++m.stats.revision;  // every call that may change the graph
  ++m.held_epoch;      // held keyframes move: every held sum is taken afresh
  // The newest keyframe the job held that is still here: what a newer node was built on.
  std::int32_t anchor = m.newest;
  while (anchor != kNone &&
         !j.Held(static_cast<std::size_t>(anchor), m.keyframes[static_cast<std::size_t>(anchor)]))
    anchor = m.keyframes[static_cast<std::size_t>(anchor)].prev;
  // What carries a newer node: the anchor from where it is now to where the solve puts it.
  const Eigen::Isometry3d C_anchor = anchor != kNone
                                         ? j.solved.Pose(static_cast<std::size_t>(anchor)) *
                                               m.Pose(static_cast<std::uint32_t>(anchor)).inverse()
                                         : Eigen::Isometry3d::Identity();
  // The anchor's height before the correction (C_anchor maps from there): for rooms, in 2-D.
  const double anchor_z_m =
      anchor != kNone ? m.keyframes[static_cast<std::size_t>(anchor)].t[2] : 0.0;
  const Values& b = j.begin;
  const Values& x = j.solved;
  for (std::size_t k = 0; k < m.keyframe_high_water; ++k) {
    KeyframeNode& node = m.keyframes[k];
    if (!node.active) continue;
    if (j.Held(k, node)) {
      // The solution itself: the local solves since may have pulled this keyframe towards a
      // loop the solution holds in full already. The next local solve brings back what newer
      // observations say.
      std::copy(&x.kq[4 * k], &x.kq[4 * k] + 4, node.q);
      std::copy(&x.kt[3 * k], &x.kt[3 * k] + 3, node.t);
    } else {
      m.SetPose(static_cast<std::uint32_t>(k), C_anchor * m.Pose(static_cast<std::uint32_t>(k)));
    }
  }
  for (std::size_t i = 0; i < m.plane_count; ++i) {
    PlaneNode& p = m.planes[i];
    if (!p.in_problem) continue;
    if (i < j.plane_count && j.plane_in[i]) {
      std::copy(&x.pn[3 * i], &x.pn[3 * i] + 3, p.n);
      p.d[0] = x.pd[i];
      continue;
    }
    // n.p + d = 0 carried by p' = C p: n' = R n, d' = d - n'.t.
    const Eigen::Vector3d n =
        (C_anchor.linear() * Eigen::Vector3d(p.n[0], p.n[1], p.n[2])).normalized();
    p.d[0] -= n.dot(C_anchor.translation());
    std::copy(n.data(), n.data() + 3, p.n);
  }
  const auto carry = [&](double* c, const double* c_begin, const double* c_solved, bool held) {
    if (held) {
      c[0] += c_solved[0] - c_begin[0];
      c[1] += c_solved[1] - c_begin[1];
      return;
    }
    const Eigen::Vector3d moved = C_anchor * Eigen::Vector3d(c[0], c[1], anchor_z_m);
    c[0] = moved.x();
    c[1] = moved.y();
  };
  for (std::size_t i = 0; i < m.room_count; ++i) {
    RoomNode& r = m.rooms[i];
    if (!r.in_problem) continue;
    carry(r.c, &b.rc[2 * i], &x.rc[2 * i], i < j.room_count && j.room_in[i]);
  }
  if (m.problem->HasParameterBlock(m.floor_c)) carry(m.floor_c, b.floor, x.floor, j.floor_in);
  // Solved without priors and none added since: their pull is gone.
  if (report.converged && j.priors_at_copy == 0 && j.prior_adds_at_copy == m.prior_adds) m.prior_pull = false;
  ++m.stats.background_applied;
  DropFullSolve(job);
  return report;
}

}  // namespace msgraphs::core
