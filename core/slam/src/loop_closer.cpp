// SPDX-License-Identifier: MIT
#include "msgraphs/core/slam/loop_closer.hpp"
#include "msgraphs/base/snapshot_archive.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "msgraphs/core/perception/covariances.hpp"

namespace msgraphs::core {

Status LoopClosureConfig::Validate() const {
  if (auto s = scan_context.Validate(); !s) return s;
  if (auto s = vgicp.Validate(); !s) return s;
  if (!(min_path_gap_m > 0) || !(reach_base_m > 0) || !(reach_per_m >= 0) || !(max_reach_m > 0) ||
      !(max_fitness_m2 > 0) || !(min_overlap > 0 && min_overlap <= 1) ||
      !(voxel_resolution_m > 0) || !(sigma_m > 0) || max_verifications < 1 ||
      !(max_chi2_after_solve > 0)) {
    return Error{Errc::kInvalidConfig,
                 "loop closure: thresholds must be positive (overlap in (0, 1])"};
  }
  return Ok();
}

Matrix6d InformationFromHessian(const Matrix6d& hessian, double sigma_m) {
  const Matrix6d symmetric = 0.5 * (hessian + hessian.transpose());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> translational(symmetric.topLeftCorner<3, 3>());
  const double strongest = translational.eigenvalues().maxCoeff();
  Matrix6d information = Matrix6d::Identity() / (sigma_m * sigma_m);
  if (!symmetric.allFinite() || !(strongest > 0)) return information;
  Matrix6d scaled = symmetric / (sigma_m * sigma_m * strongest);
  // Keep it positive definite: a floor of (100 sigma)^-2 on every direction.
  scaled += Matrix6d::Identity() / (1e4 * sigma_m * sigma_m);
  return scaled.allFinite() ? scaled : information;
}

Status LoopCloser::Init(std::size_t max_keyframes,
                        std::size_t max_points,
                        const LoopClosureConfig& config) {
  if (auto s = config.Validate(); !s) return s;
  config_ = config;
  entries_.assign(max_keyframes, Entry{});
  cells_per_keyframe_ =
      static_cast<std::size_t>(config.scan_context.rings * config.scan_context.sectors);
  cells_.assign(max_keyframes * cells_per_keyframe_, 0.0f);
  candidates_.reserve(max_keyframes);
  target_normals_.Init(max_points);
  target_covariances_.Init(max_points);
  target_tree_.Init(max_points);
  target_map_.Init(max_points);
  vgicp_.Init(max_points);
  last_loop_path_m_ = -1e300;
  stats_ = {};
  return Ok();
}

Status LoopCloser::AddKeyframe(std::uint32_t keyframe,
                               std::uint64_t sequence,
                               double path_m,
                               std::span<const Eigen::Vector3f> cloud_base) {
  if (keyframe >= entries_.size())
    return Error{Errc::kInvalidArgument, "loop closer: keyframe id beyond capacity"};
  Entry& e = entries_[keyframe];
  e.valid = false;
  if (auto s = latest_.Build(cloud_base, config_.scan_context); !s) return s;
  latest_keyframe_ = keyframe;
  float* out = cells_.data() + keyframe * cells_per_keyframe_;
  for (int r = 0; r < latest_.rings(); ++r) {
    for (int c = 0; c < latest_.sectors(); ++c) *out++ = latest_.cell(r, c);
  }
  e.sequence = sequence;
  e.path_m = path_m;
  e.valid = true;
  return Ok();
}

bool LoopCloser::DetectImpl(SGraph& graph,
                            std::uint32_t keyframe,
                            std::span<const Eigen::Vector3f> source,
                            std::span<const Eigen::Matrix3f> source_covariances,
                            CloudFn cloud_of,
                            const void* ctx) {
  if (keyframe >= entries_.size() || !entries_[keyframe].valid || keyframe != latest_keyframe_)
    return false;
  const Entry& self = entries_[keyframe];
  if (self.path_m - last_loop_path_m_ < config_.min_loop_spacing_m) return false;
  ++stats_.queries;
  const Eigen::Isometry3d T_map_new = graph.keyframe_pose(keyframe);
  candidates_.clear();
  for (std::uint32_t k = 0; k < entries_.size() && k < graph.keyframe_slots(); ++k) {
    const Entry& e = entries_[k];
    if (k == keyframe || !e.valid || !graph.keyframe_active(k)) continue;
    const double gap = self.path_m - e.path_m;
    if (gap < config_.min_path_gap_m) continue;
    const double reach =
        std::min(config_.max_reach_m, config_.reach_base_m + config_.reach_per_m * gap);
    if ((graph.keyframe_pose(k).translation() - T_map_new.translation()).head<2>().norm() > reach)
      continue;
    const std::span<const float> cells(cells_.data() + k * cells_per_keyframe_,
                                       cells_per_keyframe_);
    if (!candidate_.FromCells(config_.scan_context.rings, config_.scan_context.sectors,
                              config_.scan_context.max_radius_m, cells)) {
      continue;
    }
    const auto match = ScanContextDistance(latest_, candidate_);
    if (!match || match->distance > config_.max_scan_context_distance) continue;
    // Evicted from the full cloud store (its place keeps another cloud): counted, and never
    // given one of the max_verifications.
    if (cloud_of(ctx, k, e.sequence).empty()) {
      ++stats_.cloud_evicted;
      continue;
    }
    candidates_.emplace_back(match->distance, k);
  }
  if (candidates_.empty()) return false;
  stats_.candidates += candidates_.size();
  std::sort(candidates_.begin(), candidates_.end());
  for (std::size_t i = 0; i < candidates_.size() && i < config_.max_verifications; ++i) {
    const std::uint32_t k = candidates_[i].second;
    const std::span<const Eigen::Vector3f> target = cloud_of(ctx, k, entries_[k].sequence);
    if (target.size() < 50 || target.size() > target_tree_.capacity()) {
      ++stats_.cloud_evicted;
      continue;
    }
    if (!target_tree_.Build(target)) continue;
    if (!EstimateCovariances(target, target_tree_, {}, target_normals_, target_covariances_))
      continue;
    if (!target_map_.Build(target, target_covariances_.span(), config_.voxel_resolution_m))
      continue;
    ++stats_.verified;
    const Eigen::Isometry3d guess = graph.keyframe_pose(k).inverse() * T_map_new;
    auto result = vgicp_.Align(source, source_covariances, target_map_, target, target_tree_, guess,
                               config_.vgicp);
    if (!result || !result->converged) {
      ++stats_.rejected_not_converged;
      continue;
    }
    if (result->fitness > config_.max_fitness_m2) {
      ++stats_.rejected_fitness;
      continue;
    }
    if (static_cast<double>(result->correspondences) <
        config_.min_overlap * static_cast<double>(source.size())) {
      ++stats_.rejected_overlap;
      continue;
    }
    const Matrix6d information = InformationFromHessian(result->hessian, config_.sigma_m);
    auto factor = graph.AddRelativePose(k, keyframe, result->T_target_source, information,
                                        RelativePoseKind::kLoopClosure);
    if (!factor) continue;
    ++stats_.accepted;
    stats_.last_factor = *factor;
    stats_.last_from = k;
    stats_.last_to = keyframe;
    stats_.last_fitness_m2 = result->fitness;
    stats_.last_correction_m = (guess.inverse() * result->T_target_source).translation().norm();
    last_loop_path_m_ = self.path_m;
    return true;
  }
  return false;
}

}  // namespace msgraphs::core

namespace msgraphs::core {

bool LoopCloser::RejectIfContradicted(SGraph& graph) {
  return RejectIfContradicted(graph, stats_.last_factor, nullptr);
}

bool LoopCloser::RejectIfContradicted(SGraph& graph,
                                      std::uint32_t factor,
                                      const SGraphSolveJob* job) {
  if (!graph.IsLoopFactor(factor)) return false;  // freed by sparsification (and maybe reused)
  const auto chi2 = job != nullptr ? graph.FactorChi2(*job, factor) : graph.FactorChi2(factor);
  if (!chi2 || *chi2 <= config_.max_chi2_after_solve) return false;
  if (!graph.RemoveFactor(factor)) return false;
  ++stats_.rejected_after_solve;
  --stats_.accepted;
  return true;
}


// The keyframes' descriptors and where they were on the path; the target and candidate buffers
// are filled afresh by each detection.
template <class Archive>
void LoopCloser::Io(Archive& ar) {
  IoSameSize(ar, entries_.size());
  IoSameSize(ar, cells_.size());
  if (ar.failed()) return;
  // A descriptor only where its keyframe is listed (the search reads no other).
  for (std::size_t k = 0; k < entries_.size(); ++k) {
    Entry& e = entries_[k];
    ar(e.sequence);
    ar(e.path_m);
    IoBool(ar, e.valid);
    if (e.valid) ar(cells_.data() + k * cells_per_keyframe_, cells_per_keyframe_);
  }
  ar(last_loop_path_m_);
  ar(stats_);
}

void LoopCloser::Save(SnapshotWriter& w) const { const_cast<LoopCloser*>(this)->Io(w); }
void LoopCloser::Load(SnapshotReader& r) { Io(r); }

}  // namespace msgraphs::core
