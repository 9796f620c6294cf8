// SPDX-License-Identifier: MIT
// A full solve of an S-Graph run away from it (docs/s-graph.md, "The full solve in the
// background").
//
// A full solve costs in proportion to the graph (300 ms at 4,000 keyframes), too long for the
// thread that takes a keyframe every few hundred milliseconds. So it is split in three:
// - SGraph::BeginFullSolve (the graph's thread) copies every estimate and the list of residual
//   blocks into the job: memory copies, no solving;
// - Run (any thread) solves that copy while the graph goes on taking keyframes, local solves
//   and removals. It touches only the job's memory and the graph's cost functions and losses,
//   which never change once made; the graph keeps every one it removes while a job borrows them;
// - SGraph::ApplyFullSolve (the graph's thread) puts the solution back: keyframes and planes in
//   the job take the solution, nodes added since move rigidly with the newest keyframe the job
//   held (from where it is now to its solution), rooms and the floor take the solution plus
//   their change since the copy.
//
// Who runs it: whoever claims it first. A worker thread calls TryClaim and then Run; the graph's
// thread calls Complete at its apply point, which runs the job itself if nobody claimed it and
// otherwise waits for the worker. The result is the same with or without a worker and whatever
// its timing: the copy is taken at a fixed point and applied at a fixed point.
//
// The same copy serves the walls' marginal covariances (SGraph::BeginPlaneMarginals): Run then
// computes them at the copied estimates instead of solving (or, for a copy without the plane
// priors, after solving it without them), and the job lends the graph's costs back as soon as
// Run returns; the caller reads the result after Complete and Releases the job.
//
// Memory: Init sizes the copy from the graph's config (allocates); BeginFullSolve and
// ApplyFullSolve do not allocate beyond that. Run allocates (it builds a Ceres problem): it is
// the background path. The graph must outlive a job that borrows from it, and a job must be
// applied, dropped or released before its graph is re-initialised (SGraph::Init refuses) or
// destroyed; a job destroyed while it borrows gives the graph its borrower slot back (a full
// solve's graph then still refuses the next BeginFullSolve: drop it instead). A thread that
// runs a job must be joined before the job is destroyed (Run touches the job after it has
// published "done"). At most four jobs borrow from one graph at once.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <span>

#include "msgraphs/base/expected.hpp"
#include "msgraphs/core/graph/s_graph.hpp"

namespace msgraphs::core {

class SGraphSolveJob {
 public:
  SGraphSolveJob();
  ~SGraphSolveJob();
  SGraphSolveJob(const SGraphSolveJob&) = delete;
  SGraphSolveJob& operator=(const SGraphSolveJob&) = delete;

  /// Sizes the copy for graphs made with `config` (allocates).
  Status Init(const SGraphConfig& config);

  /// A begun job that nobody runs yet becomes this caller's: true, then call Run. False when
  /// there is nothing to run or somebody else has it. Any thread.
  bool TryClaim();
  /// Solves the copy (after a successful TryClaim). Any thread; allocates.
  void Run();
  /// The graph's thread, before ApplyFullSolve: runs the job here if nobody claimed it, else
  /// waits until its runner is done.
  void Complete();

  /// Begun and not yet applied or dropped.
  bool pending() const;
  /// Solved (Run has returned) and not yet applied or dropped.
  bool done() const;
  /// The solve's report, once done.
  const SGraphSolveReport& report() const;

  /// A marginals job (SGraph::BeginPlaneMarginals), once done: the planes asked for, in order,
  /// and each one's covariance over (alpha, beta, delta_d) along its basis_u / basis_v. Empty
  /// covariances when the computation failed (a rank-deficient problem).
  std::span<const std::uint32_t> marginal_planes() const;
  std::span<const Eigen::Matrix3d> plane_marginals() const;
  /// A marginals job, once done: the estimates its covariances were computed at (the copy's;
  /// solved without the plane priors when a PlaneEvidence::kOwn copy left any out). False for
  /// a plane, room or floor the copy did not hold, or before the job is done.
  bool PlaneEstimate(std::uint32_t plane, Eigen::Vector3d& normal, double& d) const;
  bool RoomCentre(std::uint32_t room, Eigen::Vector2d& centre) const;
  bool FloorCentre(Eigen::Vector2d& centre) const;
  /// Once done: the plane priors a kOwn copy left out; whether it was solved before its
  /// covariances (priors left out, or the graph's estimates held their pull:
  /// SGraph::estimates_hold_priors; otherwise its estimates are the graph's at the copy); that
  /// solve finished with finite values (true when there was none), and converged (within its
  /// iteration cap; no time limit).
  std::size_t priors_left_out() const;
  bool own_solved() const;
  bool own_solve_usable() const;
  bool own_solve_converged() const;
  /// A marginals job back to idle (its results go): one nobody claimed is not run, one running
  /// is waited for. A full solve is finished by its graph instead (ApplyFullSolve,
  /// DropFullSolve): kInvalidArgument.
  Status Release();

 private:
  friend class SGraph;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace msgraphs::core
