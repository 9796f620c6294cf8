// SPDX-License-Identifier: MIT
// The local solve's held sums (docs/s-graph.md, "Local solve"): a free plane's observations by
// held keyframes, one quadratic per plane, kept between local solves. A keyframe leaving the
// window adds its observations; a plane's sum is taken afresh when held keyframes may have
// moved (held_epoch: a full solve, applied or on the spot), when one of its observations goes,
// or when one is added by a keyframe the sum covers. So the summing costs what the newest
// keyframes add, not what the plane has gathered over the mission.
#include <ceres/ceres.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <vector>

#include "s_graph_impl.hpp"

namespace msgraphs::core {

const KeyframeNode* SGraph::Impl::KeyframeOfBlock(const double* q) const {
  if (keyframes.empty()) return nullptr;
  const auto base = reinterpret_cast<std::uintptr_t>(keyframes.data());
  const auto at = reinterpret_cast<std::uintptr_t>(q);
  if (at < base) return nullptr;
  const std::size_t index = (at - base) / sizeof(KeyframeNode);
  if (index >= keyframes.size() || keyframes[index].q != q) return nullptr;
  return &keyframes[index];
}

PlaneNode* SGraph::Impl::FreePlaneOf(const double* normal_block) {
  const auto at = std::lower_bound(
      window_free_planes.begin(), window_free_planes.end(), normal_block,
      [](const std::pair<const double*, std::uint32_t>& e, const double* n) { return e.first < n; });
  if (at == window_free_planes.end() || at->first != normal_block) return nullptr;
  return &planes[at->second];
}

bool SGraph::Impl::IsFreePlaneOffset(const double* block) const {
  for (const auto& [n, i] : window_free_planes)
    if (planes[i].d == block) return true;
  return false;
}

void SGraph::Impl::UpdateHeldSums() {
  const double window_s = window_oldest_free_s;
  // Each observation's Huber kernel is evaluated at the estimate when it is summed (a
  // reweighted step): the plane moves little while its keyframes are held, and every sum is
  // taken afresh after a full solve.
  bool any_kept = false;
  double kept_from_s = std::numeric_limits<double>::infinity();
  for (const auto& [n, i] : window_free_planes) {
    const PlaneNode& p = planes[i];
    if (!config.incremental_held_sums || p.held_epoch != held_epoch || p.held_before_s > window_s)
      continue;
    any_kept = true;
    kept_from_s = std::min(kept_from_s, p.held_before_s);
  }
  // The keyframes that left the window since the kept sums were taken, newest first; no more
  // than a window's worth (a plane out of the window longer is summed afresh below).
  double unwalked_s = -std::numeric_limits<double>::infinity();
  std::int32_t k = window_oldest_free != kNone
                       ? keyframes[static_cast<std::size_t>(window_oldest_free)].prev
                       : newest;
  for (std::size_t walked = 0; any_kept && k != kNone; ++walked) {
    const KeyframeNode& node = keyframes[static_cast<std::size_t>(k)];
    if (node.stamp_s < kept_from_s || walked == config.local_window_keyframes) {
      unwalked_s = node.stamp_s;
      break;
    }
    problem->GetResidualBlocksForParameterBlock(node.q, &scratch_residuals);
    SortBySlot(scratch_residuals);  // a sum's rounding must not follow Ceres' hash order
    for (ceres::ResidualBlockId id : scratch_residuals) {
      const auto* cost =
          dynamic_cast<const sgraph::PlaneCost*>(problem->GetCostFunctionForResidualBlock(id));
      if (cost == nullptr) continue;
      problem->GetParameterBlocksForResidualBlock(id, &scratch_blocks);
      PlaneNode* p = FreePlaneOf(scratch_blocks[2]);
      if (p == nullptr || p->held_epoch != held_epoch || node.stamp_s < p->held_before_s) continue;
      SumHeldObservation(*p, *cost, scratch_blocks, problem->GetLossFunctionForResidualBlock(id));
      ++stats.held_observations_added;
    }
    k = node.prev;
  }
  for (const auto& [n, i] : window_free_planes) {
    PlaneNode& p = planes[i];
    // Kept only if current and every keyframe from its boundary to the window's was walked.
    const bool kept = config.incremental_held_sums && p.held_epoch == held_epoch &&
                      p.held_before_s <= window_s && p.held_before_s > unwalked_s;
    if (!kept) RebuildHeldSum(p);
    p.held_epoch = held_epoch;
    p.held_before_s = window_s;
  }
}

void SGraph::Impl::RebuildHeldSum(PlaneNode& plane) {
  ++stats.held_sums_rebuilt;
  plane.held_H.setZero();
  plane.held_g.setZero();
  plane.held_observations = 0;
  problem->GetResidualBlocksForParameterBlock(plane.n, &scratch_residuals);
  SortBySlot(scratch_residuals);  // a sum's rounding must not follow Ceres' hash order
  for (ceres::ResidualBlockId id : scratch_residuals) {
    const auto* cost =
        dynamic_cast<const sgraph::PlaneCost*>(problem->GetCostFunctionForResidualBlock(id));
    if (cost == nullptr) continue;
    problem->GetParameterBlocksForResidualBlock(id, &scratch_blocks);
    const KeyframeNode* keyframe = KeyframeOfBlock(scratch_blocks[0]);
    if (keyframe == nullptr || keyframe->stamp_s >= window_oldest_free_s) continue;
    SumHeldObservation(plane, *cost, scratch_blocks, problem->GetLossFunctionForResidualBlock(id));
  }
}

void SGraph::Impl::SumHeldObservation(PlaneNode& p,
                                      const sgraph::PlaneCost& cost,
                                      const std::vector<double*>& blocks,
                                      const ceres::LossFunction* loss) {
  const sgraph::PlaneResidual& z = cost.functor();
  const double* q = blocks[0];
  const double* t = blocks[1];
  const Eigen::Matrix3d R = Eigen::Quaterniond(q[3], q[0], q[1], q[2]).normalized().toRotationMatrix();
  Eigen::Matrix<double, 3, 4> A = Eigen::Matrix<double, 3, 4>::Zero();
  A.block<1, 3>(0, 0) = (R * z.basis_u).transpose();
  A.block<1, 3>(1, 0) = (R * z.basis_v).transpose();
  A.block<1, 3>(2, 0) = Eigen::Vector3d(t[0], t[1], t[2]).transpose();
  A(2, 3) = 1.0;
  const Eigen::Vector3d b(0, 0, z.d_measured);
  const Eigen::Matrix<double, 3, 4> SA = z.sqrt_information * A;
  const Eigen::Vector3d Sb = z.sqrt_information * b;
  double weight = 1.0;
  if (loss != nullptr) {
    const Eigen::Vector4d x(blocks[2][0], blocks[2][1], blocks[2][2], blocks[3][0]);
    double rho[3];
    loss->Evaluate((SA * x - Sb).squaredNorm(), rho);
    weight = rho[1];
  }
  p.held_H += weight * SA.transpose() * SA;
  p.held_g += weight * SA.transpose() * Sb;
  ++p.held_observations;
}

}  // namespace msgraphs::core
