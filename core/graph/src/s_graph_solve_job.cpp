// SPDX-License-Identifier: MIT
// The solve job itself (s_graph_solve_job.hpp): sizing, claiming, running and the results. The
// graph's side, which fills it and applies it, is in s_graph_background.cpp.
#include <ceres/ceres.h>

#include <algorithm>
#include <atomic>

#include "msgraphs/core/graph/s_graph_solve_job.hpp"
#include "s_graph_solve_job_impl.hpp"

namespace msgraphs::core {

using sgraph::JobKind;
using sgraph::JobResidual;
using sgraph::Values;
using sgraph::kDone;
using sgraph::kIdle;
using sgraph::kReady;
using sgraph::kRunning;

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
  for (Values* v : {&j.begin, &j.solved}) v->Size(keyframes, planes, rooms);
  j.stamp.assign(keyframes, 0.0);
  j.keyframe_in.assign(keyframes, 0);
  j.plane_in.assign(planes, 0);
  j.room_in.assign(rooms, 0);
  // Every factor record is one residual block of at most 4 parameter blocks, except a room's
  // (9: its centre and four planes' normal and offset), one per room.
  j.residuals.reserve(config.max_factors);
  j.refs.reserve(config.max_factors * 4 + config.max_rooms * 5);
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
    const auto solve = [&](bool time_limited) {
      if (problem.NumResidualBlocks() == 0) {
        report.usable = report.converged = true;
        return;
      }
      ceres::Solver::Options solver = sgraph::SolverOptions(j.config, SolveKind::kFull);
      if (!time_limited) solver.max_solver_time_in_seconds = 1e9;  // the iteration cap only
      ceres::Solver::Summary summary;
      ceres::Solve(solver, &problem, &summary);
      report.iterations = static_cast<int>(summary.iterations.size());
      report.initial_cost = summary.initial_cost;
      report.final_cost = summary.final_cost;
      report.seconds = summary.total_time_in_seconds;
      report.converged = summary.termination_type == ceres::CONVERGENCE;
      report.usable = sgraph::SolverFinished(summary) && x.Finite();
    };
    if (j.kind == JobKind::kMarginals) {
      // Without the priors the copy's estimates are not its optimum: they hold the pull of what
      // the priors said. Solved first, its estimates and covariances are the own evidence's.
      // No time limit: the result must not depend on the machine's load (the evaluation's
      // lock-step missions run this at the exchange); the iteration cap bounds it.
      j.own_solve_usable = j.own_solve_converged = true;
      if (j.solve_first) {
        solve(false);
        j.own_solve_usable = report.usable;
        j.own_solve_converged = report.converged;
      }
      j.marginals_ok = j.own_solve_usable &&
                       static_cast<bool>(sgraph::PlaneCovariances(
                           problem, j.marginal_blocks, std::span(j.marginals).first(j.marginal_blocks.size())));
      report.usable = report.converged = j.marginals_ok;
    } else {
      solve(true);
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

bool SGraphSolveJob::PlaneEstimate(std::uint32_t plane, Eigen::Vector3d& normal, double& d) const {
  const Impl& j = *impl_;
  if (j.kind != JobKind::kMarginals || !j.Done() || plane >= j.plane_count || !j.plane_in[plane])
    return false;
  normal = Eigen::Vector3d(&j.solved.pn[3 * plane]).normalized();
  d = j.solved.pd[plane];
  return true;
}
bool SGraphSolveJob::RoomCentre(std::uint32_t room, Eigen::Vector2d& centre) const {
  const Impl& j = *impl_;
  if (j.kind != JobKind::kMarginals || !j.Done() || room >= j.room_count || !j.room_in[room])
    return false;
  centre = Eigen::Vector2d(&j.solved.rc[2 * room]);
  return true;
}
bool SGraphSolveJob::FloorCentre(Eigen::Vector2d& centre) const {
  const Impl& j = *impl_;
  if (j.kind != JobKind::kMarginals || !j.Done() || !j.floor_in) return false;
  centre = Eigen::Vector2d(j.solved.floor);
  return true;
}
std::size_t SGraphSolveJob::priors_left_out() const {
  const Impl& j = *impl_;
  return j.kind == JobKind::kMarginals && j.Done() ? j.priors_left_out : 0;
}
bool SGraphSolveJob::own_solved() const {
  const Impl& j = *impl_;
  return j.kind == JobKind::kMarginals && j.Done() && j.solve_first;
}
bool SGraphSolveJob::own_solve_usable() const {
  const Impl& j = *impl_;
  return j.kind == JobKind::kMarginals && j.Done() && j.own_solve_usable;
}
bool SGraphSolveJob::own_solve_converged() const {
  const Impl& j = *impl_;
  return j.kind == JobKind::kMarginals && j.Done() && j.own_solve_converged;
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

}  // namespace msgraphs::core
