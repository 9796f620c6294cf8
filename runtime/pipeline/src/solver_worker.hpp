// SPDX-License-Identifier: MIT
// A job off the SLAM thread (SGraphSolveJob): the node has two of these threads, one for the
// mapper's full solve (LocalMapperConfig::full_solve_lag_keyframes, docs/s-graph.md), offered
// after the keyframe that began it, one for the walls' marginal covariances (Distiller,
// MarginalsTiming::kBackground), offered after the exchange that began them, so that a long one
// of either kind never holds up the other. This thread claims and runs what it is offered. Whoever claims the job first runs it, so an offer this thread
// takes too late (the mapper reached the job's keyframe and ran it) is simply not claimed.
#pragma once

#include <condition_variable>
#include <functional>
#include <mutex>

#include "msgraphs/core/graph/s_graph_solve_job.hpp"

namespace msgraphs::runtime {

class SolverWorker {
 public:
  /// SLAM thread: `job` may be run (it must outlive the worker's loop: the node joins this
  /// thread before its mapper goes).
  void Offer(core::SGraphSolveJob* job);
  /// The thread's body, until `stop` says so (checked every few tens of milliseconds).
  void Loop(const std::function<bool()>& stop);
  /// Jobs this thread ran.
  std::uint64_t runs() const;

 private:
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  core::SGraphSolveJob* offered_ = nullptr;
  std::uint64_t runs_ = 0;
};

}  // namespace msgraphs::runtime
