// SPDX-License-Identifier: MIT
// The solve job's state (s_graph_solve_job.hpp), shared by the job's own code
// (s_graph_solve_job.cpp) and the graph's side that fills and applies it
// (s_graph_background.cpp).
#pragma once

#include <ceres/ceres.h>
#include <ceres/sphere_manifold.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <vector>

#include "msgraphs/core/graph/s_graph.hpp"
#include "msgraphs/core/graph/s_graph_solve_job.hpp"
#include "s_graph_covariance.hpp"
#include "s_graph_impl.hpp"

namespace msgraphs::core {
namespace sgraph {

enum JobState : int { kIdle, kReady, kRunning, kDone };
enum class JobKind { kFullSolve, kMarginals };

// Every estimate of a graph, flat, by slot, in one buffer: keyframe rotations, translations,
// plane normals, offsets, room centres, the floor. One buffer, so that the blocks' addresses lie
// in that order whatever the heap does: Ceres' covariance orders the blocks by address.
struct Values {
  std::vector<double> all;
  double *kq = nullptr, *kt = nullptr, *pn = nullptr, *pd = nullptr, *rc = nullptr,
         *floor = nullptr;

  Values() = default;
  Values(const Values&) = delete;
  // Both sized alike (Init): copies the values into the memory Init made.
  Values& operator=(const Values& other) {
    std::copy(other.all.begin(), other.all.end(), all.begin());
    return *this;
  }
  void Size(std::size_t keyframes, std::size_t planes, std::size_t rooms) {
    all.assign(7 * keyframes + 4 * planes + 2 * rooms + 2, 0.0);
    kq = all.data();
    kt = kq + 4 * keyframes;
    pn = kt + 3 * keyframes;
    pd = pn + 3 * planes;
    rc = pd + planes;
    floor = rc + 2 * rooms;
  }
  Eigen::Isometry3d Pose(std::size_t k) const { return PoseOf(&kq[4 * k], &kt[3 * k]); }
  bool Finite() const {
    for (double x : all)
      if (!std::isfinite(x)) return false;
    return true;
  }
};

struct JobResidual {
  const ceres::CostFunction* cost = nullptr;
  const ceres::LossFunction* loss = nullptr;
  ceres::ResidualBlockId id = nullptr;  // in the graph's problem: FactorChi2 finds it by this
  std::uint32_t first = 0, count = 0;   // its parameter blocks: refs[first, first + count)
};

}  // namespace sgraph

struct SGraphSolveJob::Impl {
  std::atomic<int> state{sgraph::kIdle};
  bool sized = false;
  SGraphConfig config;
  sgraph::JobKind kind = sgraph::JobKind::kFullSolve;
  const void* graph = nullptr;  // the graph whose costs it borrows
  // Its borrower slot in the graph while it borrows the graph's costs; ended once
  // (EndBorrowing): by a marginals job's Run or Release, by a full solve's apply or drop. Only
  // the thread that ends it touches this pointer (the claim orders Run against Release).
  std::atomic<bool>* borrowing = nullptr;
  sgraph::Values begin, solved;
  std::vector<double> stamp;  // keyframe slots are reused: a held keyframe has the same stamp
  std::vector<std::uint8_t> keyframe_in, plane_in, room_in;
  bool floor_in = false;
  std::size_t keyframe_slots = 0, plane_count = 0, room_count = 0;
  std::int32_t origin = sgraph::kNone;
  std::vector<sgraph::JobResidual> residuals;
  std::vector<double*> refs;  // into `solved`
  // How many plane priors a kOwn copy left out: with any, Run solves the copy before its
  // covariances.
  std::size_t priors_left_out = 0;
  std::size_t priors_at_copy = 0;       // the graph's plane priors when it was copied
  std::uint64_t prior_adds_at_copy = 0;  // and its count of priors ever added
  // A kOwn copy of a graph whose estimates may hold the priors' pull: Run solves it first.
  bool solve_first = false;
  bool own_solve_usable = true, own_solve_converged = true;
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
  bool Done() const { return state.load(std::memory_order_acquire) == sgraph::kDone; }
};

}  // namespace msgraphs::core
