// SPDX-License-Identifier: MIT
// The S-Graph's two solves (docs/s-graph.md, "Solves").
//
// The graph's Ceres problem holds every node and factor, and every block in it is variable but
// the origin's: a full solve hands it to Ceres as it is. A local solve does not: Ceres prepares
// the whole problem it is given on every Solve (it walks every residual block to drop the ones
// on constant blocks), so a local solve on that problem cost in proportion to the whole graph,
// 10 ms a keyframe at 500 keyframes and 30 at 2,000, for the same 20 keyframes moving. A local
// solve builds a window problem instead: the residual blocks that touch a node of the window,
// sharing the graph's cost functions, losses, manifolds and parameter memory, with every other
// node they touch held constant. That is the program Ceres would have reduced the whole
// problem to, with one change: a free plane's observations by held keyframes (the floor's, by
// every keyframe) are summed into one exact quadratic prior. So the solution is the same (the
// held observations' Huber kernels are evaluated once, at the current estimate), and its cost
// follows the window, not the graph.
#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "msgraphs/core/graph/s_graph.hpp"
#include "s_graph_impl.hpp"
#include "s_graph_quadratic_prior.hpp"

namespace msgraphs::core {

ceres::Solver::Options sgraph::SolverOptions(const SGraphConfig& config, SolveKind kind) {
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  options.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  options.max_num_iterations =
      kind == SolveKind::kLocal ? config.local_max_iterations : config.full_max_iterations;
  options.max_solver_time_in_seconds =
      kind == SolveKind::kLocal ? config.local_max_seconds : config.full_max_seconds;
  options.num_threads = 1;  // core owns no threads
  options.function_tolerance = 1e-7;
  options.logging_type = ceres::SILENT;
  return options;
}

std::size_t SGraph::Impl::CollectWindow() {
  window_free.clear();
  window_free_planes.clear();
  // The newest keyframes, the origin never among them.
  std::int32_t window_start = newest;
  std::size_t free_keyframes = 0;
  window_oldest_free = kNone;
  for (std::int32_t k = newest; k != kNone && free_keyframes < config.local_window_keyframes;
       k = keyframes[static_cast<std::size_t>(k)].prev) {
    window_start = k;
    if (k == origin) break;
    KeyframeNode& node = keyframes[static_cast<std::size_t>(k)];
    window_free.push_back(node.q);
    window_free.push_back(node.t);
    window_oldest_free = k;
    ++free_keyframes;
  }
  // Held: every keyframe stamped before the oldest free one (the origin among them).
  window_oldest_free_s = window_oldest_free != kNone
                             ? keyframes[static_cast<std::size_t>(window_oldest_free)].stamp_s
                             : std::numeric_limits<double>::infinity();
  // A plane moves when its newest observer does. By stamp: keyframe slots are reused, and a
  // removed observer was outside the window (so older than it).
  const double window_stamp = keyframes[static_cast<std::size_t>(window_start)].stamp_s;
  for (std::size_t i = 0; i < plane_count; ++i) {
    PlaneNode& p = planes[i];
    if (!p.in_problem) continue;
    const bool free = p.info.last_observed_s >= window_stamp;
    p.window_free = free;
    if (!free) continue;
    window_free_planes.emplace_back(p.n, static_cast<std::uint32_t>(i));
    window_free.push_back(p.n);
    window_free.push_back(p.d);
  }
  // A room moves with any of its walls; the floor is held.
  for (std::size_t i = 0; i < room_count; ++i) {
    RoomNode& r = rooms[i];
    if (!r.in_problem) continue;
    const int walls = r.info.shape == RoomShape::kFourWall ? 4 : 2;
    bool free = false;
    for (int w = 0; w < walls && !free; ++w)
      free = planes[static_cast<std::size_t>(r.info.walls[static_cast<std::size_t>(w)])]
                 .window_free;
    if (free) window_free.push_back(r.c);
  }
  std::sort(window_free.begin(), window_free.end());
  std::sort(window_free_planes.begin(), window_free_planes.end());
  return free_keyframes;
}

// A problem that borrows everything: the graph owns the costs, losses and manifolds.
ceres::Problem::Options sgraph::BorrowingProblemOptions() {
  ceres::Problem::Options options;
  options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  return options;
}

void SGraph::Impl::BuildWindowProblem() {
  // The graph's problem owns them all; the window only borrows (its own sums: window_costs).
  window = std::make_unique<ceres::Problem>(sgraph::BorrowingProblemOptions());
  window_costs.clear();
  const auto is_free = [this](const double* block) {
    return std::binary_search(window_free.begin(), window_free.end(), block);
  };
  const auto add_block = [this, &is_free](double* block) {
    if (window->HasParameterBlock(block)) return;
    window->AddParameterBlock(block, problem->ParameterBlockSize(block),
                              const_cast<ceres::Manifold*>(problem->GetManifold(block)));
    if (!is_free(block) || problem->IsParameterBlockConstant(block))
      window->SetParameterBlockConstant(block);
  };
  // Every residual block on a free node, once; not a free plane's own list (mostly its
  // observations: a free keyframe's come with the keyframe, a held one's are in the plane's
  // held sum), but the few factors on planes alone.
  // With incremental_held_sums off, as before: every residual block on every free node, a free
  // plane's observations by held keyframes picked out below (the reference the tests compare
  // the incremental way against).
  const bool incremental = config.incremental_held_sums;
  window_residuals.clear();
  for (double* block : window_free) {
    if (incremental && (FreePlaneOf(block) != nullptr || IsFreePlaneOffset(block))) continue;
    problem->GetResidualBlocksForParameterBlock(block, &scratch_residuals);
    window_residuals.insert(window_residuals.end(), scratch_residuals.begin(),
                            scratch_residuals.end());
  }
  for (std::int32_t slot : plane_only_factors) {
    if (!incremental) break;
    const FactorRecord& f = factors[static_cast<std::size_t>(slot)];
    if (!f.active || (f.kind != FactorKind::kWallWall && f.kind != FactorKind::kPlanePrior))
      continue;
    problem->GetParameterBlocksForResidualBlock(f.id, &scratch_blocks);
    if (std::any_of(scratch_blocks.begin(), scratch_blocks.end(), is_free))
      window_residuals.push_back(f.id);
  }
  // By factor slot: Ceres orders its work (the fill-reducing ordering's ties, the sums) by the
  // order it is handed blocks in, and an order by address would differ between two graphs
  // with the same records.
  SortBySlot(window_residuals);
  window_residuals.erase(std::unique(window_residuals.begin(), window_residuals.end()),
                         window_residuals.end());
  std::size_t kept = 0;
  for (ceres::ResidualBlockId id : window_residuals) {
    problem->GetParameterBlocksForResidualBlock(id, &scratch_blocks);
    const ceres::CostFunction* cost = problem->GetCostFunctionForResidualBlock(id);
    // A held keyframe's observation of a free plane is in the plane's held sum (reached only
    // through the plane's own list, i.e. with incremental_held_sums off): never twice.
    if (dynamic_cast<const sgraph::PlaneCost*>(cost) != nullptr && !is_free(scratch_blocks[0]))
      continue;
    for (double* block : scratch_blocks) add_block(block);
    window->AddResidualBlock(const_cast<ceres::CostFunction*>(cost),
                             const_cast<ceres::LossFunction*>(
                                 problem->GetLossFunctionForResidualBlock(id)),
                             scratch_blocks.data(), static_cast<int>(scratch_blocks.size()));
    ++kept;
  }
  // A free plane seen by held keyframes: the floor is seen from every keyframe, a long wall
  // from hundreds. With the keyframe held the residual is linear in the plane,
  // e = A [n; d] - b, so all such observations of a plane sum exactly into one quadratic.
  UpdateHeldSums();
  for (const auto& [n, i] : window_free_planes) {
    PlaneNode& p = planes[i];
    if (p.held_observations == 0) continue;
    auto prior = sgraph::QuadraticPrior::FromNormalEquations(p.held_H, p.held_g);
    if (!prior) continue;  // nothing informative (never: an observation fixes d)
    add_block(p.n);
    add_block(p.d);
    window->AddResidualBlock(prior.get(), nullptr, p.n, p.d);
    window_costs.push_back(std::move(prior));
    ++kept;
  }
  window_residual_count = kept;  // what Ceres is handed
}

void SGraph::Impl::BuildFullProblem() {
  window = std::make_unique<ceres::Problem>(sgraph::BorrowingProblemOptions());
  window_costs.clear();
  const auto add_block = [this](double* block) {
    window->AddParameterBlock(block, problem->ParameterBlockSize(block),
                              const_cast<ceres::Manifold*>(problem->GetManifold(block)));
    if (problem->IsParameterBlockConstant(block)) window->SetParameterBlockConstant(block);
  };
  // The graph's problem, in the order of the graph's own slots: its own order is the history
  // of additions and removals (Ceres removes by swapping with the last), which a graph with
  // the same records need not share.
  for (std::size_t k = 0; k < keyframe_high_water; ++k) {
    if (!keyframes[k].active) continue;
    add_block(keyframes[k].q);
    add_block(keyframes[k].t);
  }
  for (std::size_t i = 0; i < plane_count; ++i) {
    if (!planes[i].in_problem) continue;
    add_block(planes[i].n);
    add_block(planes[i].d);
  }
  for (std::size_t i = 0; i < room_count; ++i)
    if (rooms[i].in_problem) add_block(rooms[i].c);
  if (problem->HasParameterBlock(floor_c)) add_block(floor_c);
  for (std::size_t slot = 0; slot < factor_high_water; ++slot) {
    const FactorRecord& f = factors[slot];
    if (!f.active) continue;
    problem->GetParameterBlocksForResidualBlock(f.id, &scratch_blocks);
    window->AddResidualBlock(
        const_cast<ceres::CostFunction*>(problem->GetCostFunctionForResidualBlock(f.id)),
        const_cast<ceres::LossFunction*>(problem->GetLossFunctionForResidualBlock(f.id)),
        scratch_blocks.data(), static_cast<int>(scratch_blocks.size()));
  }
}

void SGraph::Impl::WindowSnapshot(bool restore) {
  std::size_t i = 0;
  for (double* block : window_free) {
    const int size = problem->ParameterBlockSize(block);
    for (int k = 0; k < size && i < snapshot.size(); ++k, ++i) {
      if (restore)
        block[k] = snapshot[i];
      else
        snapshot[i] = block[k];
    }
  }
}

bool SGraph::Impl::WindowFinite() const {
  for (const double* block : window_free) {
    const int size = problem->ParameterBlockSize(block);
    for (int k = 0; k < size; ++k)
      if (!std::isfinite(block[k])) return false;
  }
  return true;
}

Expected<SGraphSolveReport> SGraph::Solve(SolveKind kind) {
  Impl& m = *impl_;
  ++m.stats.revision;  // every call that may change the graph
  SGraphSolveReport report;
  report.kind = kind;
  if (m.active_factors == 0) {
    report.usable = report.converged = true;  // nothing to solve
    return report;
  }
  ceres::Problem* problem = m.problem.get();
  if (kind == SolveKind::kLocal) {
    report.free_keyframes = m.CollectWindow();
    m.BuildWindowProblem();
    problem = m.window.get();
    m.stats.window_residuals_peak = std::max(m.stats.window_residuals_peak,
                                             m.window_residual_count);
  } else {
    report.free_keyframes = m.active_keyframes > 0 ? m.active_keyframes - 1 : 0;
    ++m.held_epoch;  // held keyframes move: every held sum is taken afresh
    m.BuildFullProblem();
    problem = m.window.get();
  }
  // Undo state: a local solve changes only its free blocks, so only those are kept (a full copy
  // would cost in proportion to the graph again).
  const bool local = kind == SolveKind::kLocal;
  if (local) {
    m.WindowSnapshot(false);
  } else {
    m.Snapshot(false);
  }
  ceres::Solver::Summary summary;
  if (problem->NumResidualBlocks() > 0) {
    ceres::Solve(sgraph::SolverOptions(m.config, kind), problem, &summary);
  } else {
    summary.termination_type = ceres::CONVERGENCE;  // nothing in the window moves
  }
  m.window.reset();
  ++m.stats.solves;
  report.iterations = static_cast<int>(summary.iterations.size());
  report.initial_cost = summary.initial_cost;
  report.final_cost = summary.final_cost;
  report.seconds = summary.total_time_in_seconds;
  report.converged = summary.termination_type == ceres::CONVERGENCE;
  report.usable =
      sgraph::SolverFinished(summary) && (local ? m.WindowFinite() : m.StateFinite());
  if (!report.converged) ++m.stats.solves_not_converged;
  // A converged full solve without priors holds none of their pull any more.
  if (!local && report.converged && report.usable && m.stats.plane_prior_factors == 0)
    m.prior_pull = false;
  if (!report.usable) {
    // A failed solve leaves the graph as it was.
    if (local) {
      m.WindowSnapshot(true);
    } else {
      m.Snapshot(true);
    }
    ++m.stats.solves_undone;
  }
  return report;
}

Status SGraph::RebuildProblem() {
  Impl& m = *impl_;
  if (!m.problem) return Error{Errc::kInvalidArgument, "s-graph not initialised"};
  if (m.OldestBorrower() != Impl::kNoBorrower || m.full_job_pending)
    return Error{Errc::kWouldBlock, "a job borrows from this graph"};
  ceres::Problem::Options options = sgraph::BorrowingProblemOptions();
  options.enable_fast_removal = true;  // as the graph's own (Init)
  auto rebuilt = std::make_unique<ceres::Problem>(options);
  const auto add_block = [&](double* block) {
    if (!m.problem->HasParameterBlock(block)) return;
    rebuilt->AddParameterBlock(block, m.problem->ParameterBlockSize(block),
                               const_cast<ceres::Manifold*>(m.problem->GetManifold(block)));
    if (m.problem->IsParameterBlockConstant(block)) rebuilt->SetParameterBlockConstant(block);
  };
  if (m.problem->HasParameterBlock(m.floor_c)) add_block(m.floor_c);
  for (std::size_t i = m.room_count; i-- > 0;) add_block(m.rooms[i].c);
  for (std::size_t i = m.plane_count; i-- > 0;) {
    add_block(m.planes[i].d);
    add_block(m.planes[i].n);
  }
  for (std::size_t k = m.keyframe_high_water; k-- > 0;) {
    add_block(m.keyframes[k].t);
    add_block(m.keyframes[k].q);
  }
  m.residual_index.Clear();
  for (std::size_t slot = m.factor_high_water; slot-- > 0;) {
    FactorRecord& f = m.factors[slot];
    if (!f.active) continue;
    m.problem->GetParameterBlocksForResidualBlock(f.id, &m.scratch_blocks);
    m.Bind(static_cast<std::int32_t>(slot),
           rebuilt->AddResidualBlock(
               const_cast<ceres::CostFunction*>(m.problem->GetCostFunctionForResidualBlock(f.id)),
               const_cast<ceres::LossFunction*>(m.problem->GetLossFunctionForResidualBlock(f.id)),
               m.scratch_blocks.data(), static_cast<int>(m.scratch_blocks.size())));
  }
  // The old problem owns none of the costs, losses or manifolds it shared.
  m.problem = std::move(rebuilt);
  return Ok();
}

}  // namespace msgraphs::core
