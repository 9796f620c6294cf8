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
// A marginals job (BeginPlaneMarginals) takes the same copy; Run computes the planes'
// covariances on it instead of solving and ends the job's borrowing of the graph's costs.
#include <ceres/ceres.h>
#include <ceres/sphere_manifold.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <type_traits>
#include <vector>

#include "msgraphs/core/graph/s_graph.hpp"
#include "msgraphs/core/graph/s_graph_solve_job.hpp"
#include "s_graph_covariance.hpp"
#include "s_graph_impl.hpp"

namespace msgraphs::core {
namespace {

enum JobState : int { kIdle, kReady, kRunning, kDone };
enum class JobKind { kFullSolve, kMarginals };

// Every estimate of a graph, flat, by slot.
struct Values {
  std::vector<double> kq, kt, pn, pd, rc;
  double floor[2] = {0, 0};

  Eigen::Isometry3d Pose(std::size_t k) const { return sgraph::PoseOf(&kq[4 * k], &kt[3 * k]); }
  bool Finite() const {
    for (const auto* v : {&kq, &kt, &pn, &pd, &rc})
      for (double x : *v)
        if (!std::isfinite(x)) return false;
    return std::isfinite(floor[0]) && std::isfinite(floor[1]);
  }
};

struct JobResidual {
  const ceres::CostFunction* cost = nullptr;
  const ceres::LossFunction* loss = nullptr;
  ceres::ResidualBlockId id = nullptr;  // in the graph's problem: FactorChi2 finds it by this
  std::uint32_t first = 0, count = 0;   // its parameter blocks: refs[first, first + count)
};

}  // namespace

struct SGraphSolveJob::Impl {
  std::atomic<int> state{kIdle};
  bool sized = false;
  SGraphConfig config;
  JobKind kind = JobKind::kFullSolve;
  const void* graph = nullptr;  // the graph whose costs it borrows
  // Its borrower slot in the graph while it borrows the graph's costs; ended once
  // (EndBorrowing): by a marginals job's Run or Release, by a full solve's apply or drop. Only
  // the thread that ends it touches this pointer (the claim orders Run against Release).
  std::atomic<bool>* borrowing = nullptr;
  Values begin, solved;
  std::vector<double> stamp;  // keyframe slots are reused: a held keyframe has the same stamp
  std::vector<std::uint8_t> keyframe_in, plane_in, room_in;
  bool floor_in = false;
  std::size_t keyframe_slots = 0, plane_count = 0, room_count = 0;
  std::int32_t origin = kNone;
  std::vector<JobResidual> residuals;
  std::vector<double*> refs;  // into `solved`
  std::vector<ceres::ResidualBlockId> ids;
  ceres::EigenQuaternionManifold quaternion_manifold;
  ceres::SphereManifold<3> sphere_manifold;
  SGraphSolveReport report;
  // A marginals job: the planes asked for, their blocks in `solved`, the result.
  std::vector<std::uint32_t> marginal_ids;
  std::vector<sgraph::PlaneBlocks> marginal_blocks;
  std::vector<Eigen::Matrix3d> marginals;
  bool marginals_ok = false;

  void EndBorrowing() {
    if (borrowing == nullptr) return;
    borrowing->store(false, std::memory_order_release);  // after every use of the costs
    borrowing = nullptr;
  }

  bool Held(std::size_t k, const KeyframeNode& now) const {
    return k < keyframe_slots && keyframe_in[k] && stamp[k] == now.stamp_s;
  }
};

SGraphSolveJob::SGraphSolveJob() : impl_(std::make_unique<Impl>()) {}
SGraphSolveJob::~SGraphSolveJob() {
  // A job that still borrows gives its slot back (its graph must still be there; a runner must
  // have been joined): else the graph would keep every cost it removes, and refuse Init.
  if (impl_->state.load() != kRunning) impl_->EndBorrowing();
}

Status SGraphSolveJob::Init(const SGraphConfig& config) {
  if (auto s = config.Validate(); !s) return s;
  Impl& j = *impl_;
  if (j.state.load() != kIdle) return Error{Errc::kWouldBlock, "the job is pending"};
  j.config = config;
  const std::size_t keyframes = config.max_keyframes + 1, planes = config.max_planes,
                    rooms = config.max_rooms;
  for (Values* v : {&j.begin, &j.solved}) {
    v->kq.assign(4 * keyframes, 0.0);
    v->kt.assign(3 * keyframes, 0.0);
    v->pn.assign(3 * planes, 0.0);
    v->pd.assign(planes, 0.0);
    v->rc.assign(2 * rooms, 0.0);
  }
  j.stamp.assign(keyframes, 0.0);
  j.keyframe_in.assign(keyframes, 0);
  j.plane_in.assign(planes, 0);
  j.room_in.assign(rooms, 0);
  // Every factor record is one residual block; a room's has the most parameter blocks (9).
  j.residuals.reserve(config.max_factors);
  j.ids.reserve(config.max_factors);
  j.refs.reserve(config.max_factors * 4);
  j.marginal_ids.reserve(planes);
  j.marginal_blocks.reserve(planes);
  j.marginals.assign(planes, Eigen::Matrix3d::Zero());
  j.sized = true;
  return Ok();
}

bool SGraphSolveJob::TryClaim() {
  int expected = kReady;
  return impl_->state.compare_exchange_strong(expected, kRunning, std::memory_order_acquire);
}

void SGraphSolveJob::Run() {
  Impl& j = *impl_;
  Values& x = j.solved;
  SGraphSolveReport report;
  // The problem lives in this scope only: "done" is published after it is gone, so a caller
  // that saw done may drop the job.
  {
    ceres::Problem::Options options;
    // Everything is borrowed: the graph's costs and losses, the job's manifolds and memory.
    options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    ceres::Problem problem(options);
    for (std::size_t k = 0; k < j.keyframe_slots; ++k) {
      if (!j.keyframe_in[k]) continue;
      problem.AddParameterBlock(&x.kq[4 * k], 4, &j.quaternion_manifold);
      problem.AddParameterBlock(&x.kt[3 * k], 3);
      if (static_cast<std::int32_t>(k) == j.origin) {  // the gauge, as in the graph
        problem.SetParameterBlockConstant(&x.kq[4 * k]);
        problem.SetParameterBlockConstant(&x.kt[3 * k]);
      }
    }
    for (std::size_t i = 0; i < j.plane_count; ++i) {
      if (!j.plane_in[i]) continue;
      problem.AddParameterBlock(&x.pn[3 * i], 3, &j.sphere_manifold);
      problem.AddParameterBlock(&x.pd[i], 1);
    }
    for (std::size_t i = 0; i < j.room_count; ++i)
      if (j.room_in[i]) problem.AddParameterBlock(&x.rc[2 * i], 2);
    if (j.floor_in) problem.AddParameterBlock(x.floor, 2);
    for (const JobResidual& r : j.residuals) {
      problem.AddResidualBlock(const_cast<ceres::CostFunction*>(r.cost),
                               const_cast<ceres::LossFunction*>(r.loss), j.refs.data() + r.first,
                               static_cast<int>(r.count));
    }
    report.kind = SolveKind::kFull;
    std::size_t keyframes = 0;
    for (std::size_t k = 0; k < j.keyframe_slots; ++k) keyframes += j.keyframe_in[k];
    report.free_keyframes = keyframes > 0 ? keyframes - 1 : 0;
    if (j.kind == JobKind::kMarginals) {
      j.marginals_ok = static_cast<bool>(sgraph::PlaneCovariances(
          problem, j.marginal_blocks, std::span(j.marginals).first(j.marginal_blocks.size())));
      report.usable = report.converged = j.marginals_ok;
    } else if (problem.NumResidualBlocks() == 0) {
      report.usable = report.converged = true;
    } else {
      ceres::Solver::Summary summary;
      ceres::Solve(sgraph::SolverOptions(j.config, SolveKind::kFull), &problem, &summary);
      report.iterations = static_cast<int>(summary.iterations.size());
      report.initial_cost = summary.initial_cost;
      report.final_cost = summary.final_cost;
      report.seconds = summary.total_time_in_seconds;
      report.converged = summary.termination_type == ceres::CONVERGENCE;
      report.usable = sgraph::SolverFinished(summary) && x.Finite();
    }
  }
  j.report = report;
  // The problem is gone: a marginals job needs the graph's costs no more.
  if (j.kind == JobKind::kMarginals) j.EndBorrowing();
  j.state.store(kDone, std::memory_order_release);
  j.state.notify_all();
}

void SGraphSolveJob::Complete() {
  if (TryClaim()) {
    Run();
    return;
  }
  Impl& j = *impl_;
  for (int s = j.state.load(std::memory_order_acquire); s == kRunning;
       s = j.state.load(std::memory_order_acquire)) {
    j.state.wait(kRunning, std::memory_order_acquire);
  }
}

bool SGraphSolveJob::pending() const { return impl_->state.load() != kIdle; }
bool SGraphSolveJob::done() const { return impl_->state.load() == kDone; }
const SGraphSolveReport& SGraphSolveJob::report() const { return impl_->report; }

std::span<const std::uint32_t> SGraphSolveJob::marginal_planes() const {
  return impl_->marginal_ids;
}
std::span<const Eigen::Matrix3d> SGraphSolveJob::plane_marginals() const {
  const Impl& j = *impl_;
  if (j.kind != JobKind::kMarginals || j.state.load(std::memory_order_acquire) != kDone ||
      !j.marginals_ok)
    return {};
  return std::span(j.marginals).first(j.marginal_ids.size());
}

Status SGraphSolveJob::Release() {
  Impl& j = *impl_;
  if (j.state.load() == kIdle) return Ok();
  if (j.kind != JobKind::kMarginals)
    return Error{Errc::kInvalidArgument, "a full solve is finished by its graph"};
  if (TryClaim())
    j.EndBorrowing();  // nobody ran it: it is not run now, its borrowing just ends
  else
    Complete();  // a runner has it: wait
  j.state.store(kIdle, std::memory_order_release);
  j.graph = nullptr;
  return Ok();
}

Status SGraph::BeginFullSolve(SGraphSolveJob& job) {
  Impl& m = *impl_;
  if (m.full_job_pending) return Error{Errc::kWouldBlock, "a background solve is pending"};
  if (auto s = CopyIntoJob(job); !s) return s;
  SGraphSolveJob::Impl& j = *job.impl_;
  j.kind = JobKind::kFullSolve;
  m.full_job_pending = true;
  j.state.store(kReady, std::memory_order_release);
  return Ok();
}

Status SGraph::BeginPlaneMarginals(SGraphSolveJob& job, std::span<const std::uint32_t> ids) const {
  const Impl& m = *impl_;
  SGraphSolveJob::Impl& j = *job.impl_;
  if (j.sized && ids.size() > j.marginals.size())
    return Error{Errc::kCapacityExceeded, "more planes than the job holds"};
  for (std::uint32_t id : ids) {
    if (id >= m.plane_count || !m.planes[id].in_problem)
      return Error{Errc::kNotFound, "plane marginals: plane not in the optimisation"};
  }
  if (auto s = CopyIntoJob(job); !s) return s;
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

Status SGraph::CopyIntoJob(SGraphSolveJob& job) const {
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
  m.problem->GetResidualBlocks(&j.ids);
  j.residuals.clear();
  j.refs.clear();
  for (ceres::ResidualBlockId id : j.ids) {
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
  ++m.stats.background_applied;
  DropFullSolve(job);
  return report;
}

}  // namespace msgraphs::core
