// SPDX-License-Identifier: MIT
// The S-Graph's private state (core_graph only): node and factor stores sized at Init, the
// persistent Ceres problem, and the helpers that s_graph.cpp, s_graph_solve.cpp and
// s_graph_sparsify.cpp share.
#pragma once

#include <ceres/ceres.h>
#include <ceres/sphere_manifold.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "msgraphs/base/assert.hpp"
#include "msgraphs/core/geometry/se3.hpp"
#include "msgraphs/core/graph/s_graph.hpp"
#include "msgraphs/core/graph/s_graph_solve_job.hpp"
#include "s_graph_factors.hpp"
#include "s_graph_residual_index.hpp"

namespace msgraphs::core {
namespace sgraph {

constexpr std::int32_t kNone = -1;

enum class FactorKind : std::uint8_t {
  kRelative,
  kPlane,
  kRoom,
  kWallWall,
  kFloorRoom,
  kPlanePrior
};

struct KeyframeNode {
  double q[4] = {0, 0, 0, 1};  // Eigen order: x y z w
  double t[3] = {0, 0, 0};
  double stamp_s = 0;
  std::int32_t prev = kNone, next = kNone;  // neighbours in time among active keyframes
  std::uint32_t loop_factors = 0;
  // Every relative-pose measurement from `prev` to this keyframe fused into one (information-
  // weighted in the tangent space) with the summed information: what a composed factor is
  // made of when a keyframe between them is sparsified. Measurements, not estimates: an
  // estimate taken before the next full solve would bake its error into the graph.
  Eigen::Isometry3d measurement_from_prev = Eigen::Isometry3d::Identity();
  Matrix6d information_from_prev = Matrix6d::Zero();
  bool active = false;
  bool last_observer = false;  // MarkLastObservers: the only observer left of some plane
};

struct PlaneNode {
  double n[3] = {1, 0, 0};
  double d[1] = {0};
  MapPlane info;
  bool in_problem = false;
  bool window_free = false;  // moves in the current local solve (CollectWindow)
  // MarkLastObservers' scratch: the one keyframe seen observing it, or kNone.
  std::int32_t only_observer = kNone;
  bool observers_two_or_more = false;
  // Its observations by keyframes the local solve holds, summed into one quadratic in
  // x = [n; d] (s_graph_solve.cpp): x' H x - 2 g' x. The sum holds every observation by a
  // keyframe stamped before held_before_s, and is current while held_epoch is the graph's
  // (0: never, or invalidated).
  Eigen::Matrix4d held_H = Eigen::Matrix4d::Zero();
  Eigen::Vector4d held_g = Eigen::Vector4d::Zero();
  std::uint32_t held_observations = 0;
  std::uint64_t held_epoch = 0;
  double held_before_s = 0;
};

struct RoomNode {
  double c[2] = {0, 0};
  MapRoom info;
  std::int32_t factor = kNone;
  std::int32_t floor_factor = kNone;
  bool in_problem = false;
};

struct FactorRecord {
  FactorKind kind = FactorKind::kRelative;
  RelativePoseKind relative = RelativePoseKind::kOdometry;
  std::uint32_t a = 0, b = 0;  // keyframes, keyframe and plane, planes, room, floor and room
  ceres::ResidualBlockId id = nullptr;
  bool active = false;
  // A relative factor fused into keyframe b's measurement_from_prev (a hop of the time chain):
  // sparsification composes it rather than carrying it on its own.
  bool chain = false;
};

inline bool SqrtInformation6(const Matrix6d& information, Matrix6d& sqrt_information) {
  if (!information.allFinite() || !information.isApprox(information.transpose(), 1e-6))
    return false;
  Eigen::LLT<Matrix6d> llt(information);
  if (llt.info() != Eigen::Success) return false;
  sqrt_information = llt.matrixU();
  return sqrt_information.allFinite();
}

// Adjoint of T for tangent vectors ordered [translation; rotation].
inline Matrix6d Adjoint(const Eigen::Isometry3d& T) {
  Matrix6d A = Matrix6d::Zero();
  const Eigen::Matrix3d R = T.linear();
  const Eigen::Vector3d t = T.translation();
  Eigen::Matrix3d tx;
  tx << 0, -t.z(), t.y(), t.z(), 0, -t.x(), -t.y(), t.x(), 0;
  A.topLeftCorner<3, 3>() = R;
  A.topRightCorner<3, 3>() = tx * R;
  A.bottomRightCorner<3, 3>() = R;
  return A;
}

// Two measurements of the same relative pose fused, information-weighted in the tangent space
// at the first (to first order): Z_a Exp((Omega_a + Omega_b)^-1 Omega_b Log(Z_a^-1 Z_b)). The
// fused information is the sum. Z_a when the step is not finite.
inline Eigen::Isometry3d Fuse(const Eigen::Isometry3d& Z_a,
                              const Matrix6d& information_a,
                              const Eigen::Isometry3d& Z_b,
                              const Matrix6d& information_b) {
  const Vector6d xi = Se3Log(Z_a.inverse() * Z_b);
  const Vector6d step = (information_a + information_b).ldlt().solve(information_b * xi);
  return step.allFinite() ? Eigen::Isometry3d(Z_a * Se3Exp(step)) : Z_a;
}

// A keyframe's parameter blocks (quaternion x y z w, translation) as a pose, and back.
inline Eigen::Isometry3d PoseOf(const double* q, const double* t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Quaterniond(q[3], q[0], q[1], q[2]).normalized().toRotationMatrix();
  T.translation() = Eigen::Vector3d(t[0], t[1], t[2]);
  return T;
}
inline void StorePose(const Eigen::Isometry3d& T, double* q, double* t) {
  const Eigen::Quaterniond r(T.linear());
  q[0] = r.x();
  q[1] = r.y();
  q[2] = r.z();
  q[3] = r.w();
  for (int i = 0; i < 3; ++i) t[i] = T.translation()[i];
}

// A problem that borrows the graph's costs, losses and manifolds (s_graph_solve.cpp).
ceres::Problem::Options BorrowingProblemOptions();
// The solver's options for either solve (s_graph_solve.cpp).
ceres::Solver::Options SolverOptions(const SGraphConfig& config, SolveKind kind);
// The solver stopped with a state worth keeping (converged, or at its limits, with a finite cost).
inline bool SolverFinished(const ceres::Solver::Summary& summary) {
  return (summary.termination_type == ceres::CONVERGENCE ||
          summary.termination_type == ceres::NO_CONVERGENCE ||
          summary.termination_type == ceres::USER_SUCCESS) &&
         std::isfinite(summary.final_cost);
}

// How every relative factor is built: sparsification reads a measurement back from its functor.
using RelativePoseCost = ceres::AutoDiffCostFunction<RelativePoseResidual, 6, 4, 3, 4, 3>;
// How every keyframe-to-plane factor is built: the local solve reads its measurement back.
using PlaneCost = ceres::AutoDiffCostFunction<PlaneResidual, 3, 4, 3, 3, 1>;
// The others, named so that a snapshot (s_graph_snapshot.cpp) reads each measurement back.
using RoomCost = ceres::AutoDiffCostFunction<RoomResidual, 2, 2, 3, 1, 3, 1, 3, 1, 3, 1>;
using CorridorCost = ceres::AutoDiffCostFunction<CorridorResidual, 2, 2, 3, 1, 3, 1>;
using WallWallCost = ceres::AutoDiffCostFunction<WallWallResidual, 4, 3, 1, 3, 1>;
using PlanePriorCost = ceres::AutoDiffCostFunction<PlanePriorResidual, 3, 3, 1>;
using FloorRoomCost = ceres::AutoDiffCostFunction<FloorRoomResidual, 2, 2, 2>;

}  // namespace sgraph

using sgraph::FactorKind;
using sgraph::FactorRecord;
using sgraph::KeyframeNode;
using sgraph::kNone;
using sgraph::PlaneNode;
using sgraph::RoomNode;

struct SGraph::Impl {
  ~Impl() { DeleteCosts(); }
  SGraphConfig config;
  std::unique_ptr<ceres::Problem> problem;
  ceres::EigenQuaternionManifold quaternion_manifold;
  ceres::SphereManifold<3> sphere_manifold;
  std::unique_ptr<ceres::LossFunction> huber_relative, huber_loop, huber_plane, huber_room;

  std::vector<KeyframeNode> keyframes;
  std::vector<std::int32_t> free_keyframe_slots;
  std::size_t keyframe_high_water = 0;  // slots ever used
  std::int32_t newest = kNone, origin = kNone;
  std::size_t active_keyframes = 0;

  std::vector<PlaneNode> planes;
  std::size_t plane_count = 0;
  std::vector<RoomNode> rooms;
  std::size_t room_count = 0;
  double floor_c[2] = {0, 0};
  bool floor_active = false;

  std::vector<FactorRecord> factors;
  std::vector<std::int32_t> free_factor_slots;
  std::size_t factor_high_water = 0, active_factors = 0;
  // The slot of every residual block in `problem` (s_graph_residual_index.hpp): what every
  // problem handed to Ceres is ordered by.
  sgraph::ResidualIndex residual_index;
  // Records the residual block Ceres made for factor `slot`.
  void Bind(std::int32_t slot, ceres::ResidualBlockId id) {
    factors[static_cast<std::size_t>(slot)].id = id;
    const bool listed = residual_index.Insert(id, slot);
    MSGRAPHS_ASSERT(listed, "s-graph residual index full or a block listed twice");
  }

  std::vector<double> snapshot;  // parameter values before a solve, to undo a bad one
  // Jobs (s_graph_background.cpp) borrow the graph's cost functions: a full solve from its
  // begin until it is applied or dropped, a marginals job until its Run ends (on its runner's
  // thread: the flag is atomic). Each begin takes the next generation; a removed cost is kept
  // (retired_costs, oldest first) until every job begun before its removal has ended borrowing,
  // whatever jobs begun since still borrow.
  struct Borrower {
    std::atomic<bool> borrowing{false};
    std::uint64_t generation = 0;
  };
  static constexpr std::size_t kMaxBorrowers = 4;
  std::array<Borrower, kMaxBorrowers> borrowers;
  std::uint64_t borrow_generation = 0;  // the newest begin's
  struct RetiredCost {
    const ceres::CostFunction* cost = nullptr;
    std::uint64_t generation = 0;  // borrow_generation when it was removed
  };
  std::vector<RetiredCost> retired_costs;
  std::vector<const ceres::CostFunction*> scratch_costs;
  // The job PlaneMarginals runs on the spot (made at its first call after Init).
  std::unique_ptr<SGraphSolveJob> marginals_now;
  bool full_job_pending = false;  // one full solve at a time (ApplyFullSolve carries from it)
  // Plane priors were added since the last converged full solve without any: the estimates may
  // still hold their pull (estimates_hold_priors).
  bool prior_pull = false;
  std::uint64_t prior_adds = 0;  // AddPlanePrior calls that added one (a job notes it at its copy)
  SGraphStats stats;

  // The local solve's window problem (s_graph_solve.cpp): built per local solve from the
  // residual blocks on the window's nodes, and gone after it. The vectors keep their capacity.
  std::unique_ptr<ceres::Problem> window;
  std::vector<double*> window_free;  // the window's free parameter blocks, sorted
  std::vector<std::pair<const double*, std::uint32_t>> window_free_planes;  // normal block, id
  std::vector<ceres::ResidualBlockId> window_residuals, scratch_residuals;
  std::vector<std::pair<std::int32_t, ceres::ResidualBlockId>> scratch_slotted;
  // Puts residual blocks in the order of their factor slots, not of their addresses or of
  // Ceres' hash sets (s_graph_residual_index.hpp).
  void SortBySlot(std::vector<ceres::ResidualBlockId>& ids) {
    scratch_slotted.clear();
    for (ceres::ResidualBlockId id : ids) {
      const std::int32_t slot = residual_index.Find(id);
      MSGRAPHS_ASSERT(slot != sgraph::ResidualIndex::kAbsent, "s-graph residual block without a factor");
      scratch_slotted.emplace_back(slot, id);
    }
    std::sort(scratch_slotted.begin(), scratch_slotted.end(),
              [](const auto& a, const auto& b) { return a.first < b.first; });
    for (std::size_t i = 0; i < ids.size(); ++i) ids[i] = scratch_slotted[i].second;
  }
  std::vector<double*> scratch_blocks;
  std::size_t window_residual_count = 0;  // residual blocks the last window problem held
  std::vector<std::unique_ptr<ceres::CostFunction>> window_costs;  // the held observations' sums
  // The window's oldest free keyframe (kNone: none is free) and its stamp (+inf then): every
  // keyframe stamped before it is held.
  std::int32_t window_oldest_free = kNone;
  double window_oldest_free_s = 0;
  // Goes up whenever held keyframes may have moved or lost observations (a full solve, its
  // application, sparsification): every plane's held sum is then taken afresh. Starts at 1.
  std::uint64_t held_epoch = 1;
  // Wall-wall and plane-prior factors (on planes only, no keyframe or room): the window takes
  // those on a free plane from here, not from the plane's residual blocks, which are mostly
  // its observations. May hold freed or reused slots (checked on use; compacted when full).
  std::vector<std::int32_t> plane_only_factors;
  void CompactPlaneOnlyFactors();
  // Which nodes move in a local solve: fills window_free; returns the free keyframes.
  std::size_t CollectWindow();
  void BuildWindowProblem();
  // The whole graph as a problem of its own (in `window`), blocks and factors in slot order:
  // what a full solve and the marginals on the spot hand Ceres.
  void BuildFullProblem();
  // Snapshot (restore: put back) and finiteness of the window's free blocks only. The snapshot
  // buffer holds every block of the graph, so it holds the window's.
  void WindowSnapshot(bool restore);
  bool WindowFinite() const;
  // Adds one held keyframe's observation to the plane's held_H / held_g.
  void SumHeldObservation(PlaneNode& plane,
                          const sgraph::PlaneCost& cost,
                          const std::vector<double*>& blocks,
                          const ceres::LossFunction* loss);
  // Brings every free plane's held sum up to the window (s_graph_held_sums.cpp).
  void UpdateHeldSums();
  void RebuildHeldSum(PlaneNode& plane);
  // The free plane whose normal block this is (window_free_planes), or null.
  PlaneNode* FreePlaneOf(const double* normal_block);
  bool IsFreePlaneOffset(const double* block) const;
  // The keyframe whose rotation block this is, or null.
  const KeyframeNode* KeyframeOfBlock(const double* q) const;

  bool ValidKeyframe(std::uint32_t id) const {
    return id < keyframe_high_water && keyframes[id].active;
  }
  bool ValidPlane(std::uint32_t id) const { return id < plane_count && planes[id].info.active; }
  bool ValidRoom(std::uint32_t id) const { return id < room_count && rooms[id].info.active; }

  Eigen::Isometry3d Pose(std::uint32_t id) const {
    return sgraph::PoseOf(keyframes[id].q, keyframes[id].t);
  }
  void SetPose(std::uint32_t id, const Eigen::Isometry3d& T) {
    sgraph::StorePose(T, keyframes[id].q, keyframes[id].t);
  }

  Expected<std::int32_t> NewFactor(FactorKind kind, std::uint32_t a, std::uint32_t b) {
    std::int32_t slot = kNone;
    if (!free_factor_slots.empty()) {
      slot = free_factor_slots.back();
      free_factor_slots.pop_back();
    } else if (factor_high_water < factors.size()) {
      slot = static_cast<std::int32_t>(factor_high_water++);
    } else {
      ++stats.rejected_capacity;
      return Error{Errc::kCapacityExceeded, "s-graph factor store full"};
    }
    if (kind == FactorKind::kWallWall || kind == FactorKind::kPlanePrior) {
      // Compacted while this slot is still free: at most active_factors < max_factors stay.
      // Also when stale entries outnumber live ones: priors are replaced at every exchange
      // (LocalMapper::SetPlanePriors), and the window walks this list at every local solve.
      const std::size_t live = stats.wall_wall_factors + stats.plane_prior_factors;
      if (plane_only_factors.size() == plane_only_factors.capacity() ||
          plane_only_factors.size() > 2 * live + 64)
        CompactPlaneOnlyFactors();
      plane_only_factors.push_back(slot);  // capacity max_factors (Init): never allocates
    }
    FactorRecord& f = factors[static_cast<std::size_t>(slot)];
    f = FactorRecord{};
    f.kind = kind;
    f.a = a;
    f.b = b;
    f.active = true;
    ++active_factors;
    stats.factors_peak = std::max(stats.factors_peak, active_factors);
    return slot;
  }

  // Forgets a factor record (the residual block is removed by the caller or by Ceres).
  void DropFactor(std::int32_t slot) {
    FactorRecord& f = factors[static_cast<std::size_t>(slot)];
    if (!f.active) return;
    f.active = false;
    --active_factors;
    residual_index.Erase(f.id, slot);
    switch (f.kind) {
      case FactorKind::kRelative:
        --stats.relative_factors[static_cast<std::size_t>(f.relative)];
        if (f.relative == RelativePoseKind::kLoopClosure) {
          if (keyframes[f.a].loop_factors > 0) --keyframes[f.a].loop_factors;
          if (keyframes[f.b].loop_factors > 0) --keyframes[f.b].loop_factors;
        }
        break;
      case FactorKind::kPlane:
        --stats.plane_factors;
        if (f.b < planes.size()) {
          planes[f.b].held_epoch = 0;  // its held sum may include it
          if (planes[f.b].info.live_observations > 0 &&
              --planes[f.b].info.live_observations == 0)
            ++stats.planes_unobserved;
        }
        break;
      case FactorKind::kRoom:
        --stats.room_factors;
        break;
      case FactorKind::kWallWall:
        --stats.wall_wall_factors;
        break;
      case FactorKind::kFloorRoom:
        --stats.floor_factors;
        break;
      case FactorKind::kPlanePrior:
        --stats.plane_prior_factors;
        break;
    }
    free_factor_slots.push_back(slot);  // capacity reserved at Init: no allocation
  }

  void RemoveFactor(std::int32_t slot) {
    FactorRecord& f = factors[static_cast<std::size_t>(slot)];
    if (!f.active) return;
    RemoveResidual(f.id);
    DropFactor(slot);
  }

  // The graph owns its cost functions, not the problem: a job (SGraphSolveJob) evaluates them
  // on another thread, so one removed while a job begun before borrows them is kept until that
  // job ends borrowing, never deleted under it.
  void RetireCost(const ceres::CostFunction* cost) {
    if (OldestBorrower() == kNoBorrower) {
      ReleaseRetiredCosts();
      delete cost;
      return;
    }
    // Capacity reserved at Init: a removal per factor slot between two releases.
    retired_costs.push_back({cost, borrow_generation});
    ReleaseRetiredCosts();
  }
  static constexpr std::uint64_t kNoBorrower = ~std::uint64_t{0};
  // The generation of the oldest job still borrowing (kNoBorrower: none).
  std::uint64_t OldestBorrower() const {
    std::uint64_t oldest = kNoBorrower;
    for (const Borrower& b : borrowers) {
      if (b.borrowing.load(std::memory_order_acquire)) oldest = std::min(oldest, b.generation);
    }
    return oldest;
  }
  // Frees the retired costs no borrowing job can hold: those removed before the oldest
  // borrowing job began. The runners never touch this list.
  void ReleaseRetiredCosts() {
    const std::uint64_t oldest = OldestBorrower();
    std::size_t n = 0;
    while (n < retired_costs.size() && retired_costs[n].generation < oldest) delete retired_costs[n++].cost;
    retired_costs.erase(retired_costs.begin(), retired_costs.begin() + static_cast<std::ptrdiff_t>(n));
  }
  // A slot for a job beginning now (nullptr: kMaxBorrowers jobs borrow already).
  Borrower* TakeBorrower() {
    for (Borrower& b : borrowers) {
      if (b.borrowing.load(std::memory_order_acquire)) continue;
      b.generation = ++borrow_generation;
      b.borrowing.store(true, std::memory_order_release);
      return &b;
    }
    return nullptr;
  }
  void RemoveResidual(ceres::ResidualBlockId id) {
    const ceres::CostFunction* cost = problem->GetCostFunctionForResidualBlock(id);
    problem->RemoveResidualBlock(id);
    RetireCost(cost);
  }
  // Removes a parameter block and with it every residual block on it (and their costs).
  void RemoveBlock(double* block) {
    problem->GetResidualBlocksForParameterBlock(block, &scratch_residuals);
    scratch_costs.clear();
    for (ceres::ResidualBlockId id : scratch_residuals)
      scratch_costs.push_back(problem->GetCostFunctionForResidualBlock(id));
    problem->RemoveParameterBlock(block);
    for (const ceres::CostFunction* cost : scratch_costs) RetireCost(cost);
  }
  // Every cost function the graph owns, at its end.
  void DeleteCosts() {
    window.reset();  // borrows them
    if (problem) {
      std::vector<ceres::ResidualBlockId> all;
      problem->GetResidualBlocks(&all);
      scratch_costs.clear();
      for (ceres::ResidualBlockId id : all)
        scratch_costs.push_back(problem->GetCostFunctionForResidualBlock(id));
      problem.reset();
      for (const ceres::CostFunction* cost : scratch_costs) delete cost;
    }
    for (const RetiredCost& r : retired_costs) delete r.cost;  // no job borrows (Init, ~SGraph)
    retired_costs.clear();
  }

  void EnsurePlaneInProblem(PlaneNode& p) {
    if (p.in_problem) return;
    problem->AddParameterBlock(p.n, 3, &sphere_manifold);
    problem->AddParameterBlock(p.d, 1);
    p.in_problem = true;
  }

  Expected<std::uint32_t> AddRelative(std::uint32_t from,
                                      std::uint32_t to,
                                      const Eigen::Isometry3d& T_from_to,
                                      const Matrix6d& information,
                                      RelativePoseKind kind) {
    if (!ValidKeyframe(from) || !ValidKeyframe(to) || from == to) {
      ++stats.rejected_missing_node;
      return Error{Errc::kNotFound, "relative pose between missing keyframes"};
    }
    if (!IsValidRigidTransform(T_from_to, 1e-6)) {
      ++stats.rejected_pose;
      return Error{Errc::kInvalidArgument, "relative pose is not a finite rigid transform"};
    }
    Matrix6d sqrt_information;
    if (!sgraph::SqrtInformation6(information, sqrt_information)) {
      ++stats.rejected_information;
      return Error{Errc::kInvalidArgument,
                   "relative pose information is not symmetric positive definite"};
    }
    auto slot = NewFactor(FactorKind::kRelative, from, to);
    if (!slot) return slot.error();
    auto* functor =
        new sgraph::RelativePoseResidual{Eigen::Quaterniond(T_from_to.linear()).normalized(),
                                         T_from_to.translation(), sqrt_information};
    auto* cost = new sgraph::RelativePoseCost(functor);
    ceres::LossFunction* loss =
        kind == RelativePoseKind::kLoopClosure ? huber_loop.get() : huber_relative.get();
    FactorRecord& f = factors[static_cast<std::size_t>(*slot)];
    f.relative = kind;
    Bind(*slot, problem->AddResidualBlock(cost, loss, keyframes[from].q, keyframes[from].t,
                                          keyframes[to].q, keyframes[to].t));
    ++stats.relative_factors[static_cast<std::size_t>(kind)];
    if (kind == RelativePoseKind::kLoopClosure) {
      ++keyframes[from].loop_factors;
      ++keyframes[to].loop_factors;
    } else if (keyframes[to].prev == static_cast<std::int32_t>(from)) {
      f.chain = true;
      KeyframeNode& node = keyframes[to];
      node.measurement_from_prev =
          node.information_from_prev.isZero()
              ? T_from_to
              : sgraph::Fuse(node.measurement_from_prev, node.information_from_prev, T_from_to,
                             information);
      node.information_from_prev += information;
    }
    return static_cast<std::uint32_t>(*slot);
  }

  // Sparsification (s_graph_sparsify.cpp): makes room for one keyframe. False only when no
  // keyframe lies between the origin and the local window, which the config's validation rules
  // out; AddKeyframe then refuses the keyframe rather than write past the store.
  bool Sparsify();
  // Removes keyframe v (active, between two keyframes): its loops carried to a neighbour, its
  // neighbours joined by the composed hop, its plane observations dropped, its slot freed. The
  // body of Sparsify once the victim is chosen; counts what it carries and drops, not itself.
  // Factors in `keep_factors` stay as they are (a carried loop is never fused into one).
  void RemoveKeyframe(std::uint32_t v, std::span<const std::uint32_t> keep_factors = {});
  // Carries plane observation `slot` (on keyframe v) to keyframe t: the measurement as t would
  // have made it, T_t_v its pose in t's frame and hop_covariance the covariance of T_t_v's
  // right perturbation [translation; rotation], already inflated for the hop's other uses.
  // Fused into t's own observation of the plane when t has one that agrees with it. v's factor
  // is removed either way; false (the observation is lost) when the covariances are not
  // positive definite or the factor store refuses it (s_graph_sparsify_planes.cpp).
  bool CarryPlaneObservation(std::int32_t slot,
                             std::uint32_t t,
                             const Eigen::Isometry3d& T_t_v,
                             const Matrix6d& hop_covariance,
                             bool& fused);
  // A keyframe-to-plane factor from its measurement in the residual's terms (basis, offset,
  // upper root of the information), without AddPlaneObservation's checks and bookkeeping of
  // new evidence: what sparsification puts back.
  Expected<std::int32_t> AddPlaneFactor(std::uint32_t keyframe,
                                        std::uint32_t plane,
                                        const sgraph::PlaneResidual& z);
  // Whether removing v would carry every loop on it and join its neighbours, and leave every
  // plane it sees observed (no constraint dropped): what a removal on request requires.
  bool RemovalLosesNothing(std::uint32_t v);
  // Sets every keyframe's last_observer: whether it is the only keyframe left observing some
  // plane.
  void MarkLastObservers();
  // The oldest keyframe of the local window (kNone when fewer keyframes than the window).
  std::int32_t WindowStart() const;
  // A relative factor's measurement T_a_b and information, as its residual holds them.
  void RelativeMeasurement(const FactorRecord& f,
                           Eigen::Isometry3d& T_a_b,
                           Matrix6d& information) const;
  // Adds T_from_to between two keyframes, fused into a parallel factor of the same kind (not a
  // chain hop, not one of `keep_factors`) when there is one. False when the graph refused it.
  bool AddOrFuseRelative(std::uint32_t from,
                         std::uint32_t to,
                         const Eigen::Isometry3d& T_from_to,
                         const Matrix6d& information,
                         RelativePoseKind kind,
                         std::span<const std::uint32_t> keep_factors,
                         bool& fused);

  // Every parameter value in one flat buffer (sized at Init), to undo a solve.
  void Snapshot(bool restore) {
    std::size_t i = 0;
    auto io = [&](double* v, int size) {
      for (int k = 0; k < size; ++k, ++i) {
        if (restore)
          v[k] = snapshot[i];
        else
          snapshot[i] = v[k];
      }
    };
    for (std::size_t k = 0; k < keyframe_high_water; ++k) {
      io(keyframes[k].q, 4);
      io(keyframes[k].t, 3);
    }
    for (std::size_t k = 0; k < plane_count; ++k) {
      io(planes[k].n, 3);
      io(planes[k].d, 1);
    }
    for (std::size_t k = 0; k < room_count; ++k) io(rooms[k].c, 2);
    io(floor_c, 2);
  }

  bool StateFinite() const {
    for (std::size_t k = 0; k < keyframe_high_water; ++k) {
      for (double v : keyframes[k].q)
        if (!std::isfinite(v)) return false;
      for (double v : keyframes[k].t)
        if (!std::isfinite(v)) return false;
    }
    for (std::size_t k = 0; k < plane_count; ++k) {
      for (double v : planes[k].n)
        if (!std::isfinite(v)) return false;
      if (!std::isfinite(planes[k].d[0])) return false;
    }
    for (std::size_t k = 0; k < room_count; ++k) {
      if (!std::isfinite(rooms[k].c[0]) || !std::isfinite(rooms[k].c[1])) return false;
    }
    return std::isfinite(floor_c[0]) && std::isfinite(floor_c[1]);
  }
};

}  // namespace msgraphs::core
