// SPDX-License-Identifier: MIT
// LocalMapper scan tracking: every sweep registered against the local map, so that the encoders
// are trusted over 0.1 s, not over a keyframe's metre (local_mapper.hpp, track_scans).
#include <Eigen/Geometry>
#include <algorithm>

#include "msgraphs/core/slam/local_mapper.hpp"

namespace msgraphs::core {

bool LocalMapper::EnsureLocalMap() {
  if (!have_keyframe_) return false;
  if (local_map_keyframe_ == last_keyframe_) return true;
  // A build that failed (too few points) is not retried on every sweep: the next keyframe's.
  if (local_map_failed_ == last_keyframe_) return false;
  if (!BuildLocalMap(last_keyframe_)) {
    local_map_failed_ = last_keyframe_;
    return false;
  }
  local_map_keyframe_ = last_keyframe_;
  return true;
}

Matrix6d LocalMapper::HoldingPrior(const Eigen::Isometry3d& step, bool across_gap) const {
  Matrix6d information = OdometryInformation(step, across_gap);
  const double floor_t = 1.0 / (config_.tracking_prior_sigma_m * config_.tracking_prior_sigma_m);
  const double floor_r = 1.0 / (config_.tracking_prior_sigma_rad * config_.tracking_prior_sigma_rad);
  for (int i = 0; i < 3; ++i) {
    information(i, i) = std::min(information(i, i), floor_t);
    information(i + 3, i + 3) = std::min(information(i + 3, i + 3), floor_r);
  }
  return information;
}

Eigen::Isometry3d LocalMapper::Track(const LidarScanView& scan, const Eigen::Isometry3d& T_odom_start,
                                     const Eigen::Isometry3d& T_odom_end, bool across_gap) {
  // The encoders' motion since the last tracked sweep (since the keyframe for the first one).
  if (!have_track_) {
    track_T_last_base_ = Eigen::Isometry3d::Identity();
    track_T_odom_ = last_odometry_;
    have_track_ = true;
  }
  const Eigen::Isometry3d step = track_T_odom_.inverse() * T_odom_end;
  const Eigen::Isometry3d predicted = track_T_last_base_ * step;
  track_T_last_base_ = predicted;
  track_T_odom_ = T_odom_end;
  if (!EnsureLocalMap()) {
    ++stats_.scans_untracked;
    return predicted;
  }
  PrepareSweep(scan, T_odom_start, T_odom_end, true);
  prepared_ = true;
  const Eigen::Vector3f viewpoint = config_.T_base_lidar.translation().cast<float>();
  if (!scan_voxel_.Downsample(filtered_.span(), config_.tracking_voxel_m, track_down_) ||
      track_down_.size() < 50 || !track_tree_.Build(track_down_.span()) ||
      !EstimateCovariances(track_down_.span(), track_tree_, {}, track_normals_, track_covariances_,
                           &viewpoint)) {
    ++stats_.scans_untracked;
    return predicted;
  }
  // The prior: the encoders' step, never tighter than the tracking floor (a slip within one
  // sweep must stay correctable wherever the clouds constrain anything).
  VgicpPrior prior;
  prior.T_target_source = predicted;
  prior.information = HoldingPrior(step, across_gap);
  prior.clouds_sigma_m = config_.scan_match_sigma_m;
  auto result = vgicp_.Align(track_down_.span(), track_covariances_.span(), local_map_,
                             local_points_.span(), local_tree_, predicted, config_.scan_matching,
                             nullptr, &prior);
  // The keyframe's tests but fitness, with the correction bounded by what the slips since the
  // last tracked sweep can have put in: a few prior sigmas a sweep, at most the keyframe's bound
  // (a wrong minimum further away would carry into every later sweep). No fitness limit: a
  // sweep walking down a corridor sees new space the local map does not hold, which fitness
  // counts as misfit (the keyframes' 0.05 m2 refused one correct match in eight, and the
  // slipped steps among them: docs/s-graph.md), while a wrong fit does not look worse.
  const double sweeps = 1.0 + static_cast<double>(untracked_sweeps_);
  const double bound_m = std::min(config_.max_correction_m, 3 * config_.tracking_prior_sigma_m * sweeps);
  const double bound_rad = std::min(config_.max_correction_rad, 3 * config_.tracking_prior_sigma_rad * sweeps);
  ++untracked_sweeps_;  // until it passes
  if (!result || !result->converged ||
      static_cast<double>(result->correspondences) <
          config_.scan_match_min_overlap * static_cast<double>(track_down_.size())) {
    ++stats_.scans_untracked;
    return predicted;
  }
  const Eigen::Isometry3d correction = predicted.inverse() * result->T_target_source;
  if (correction.translation().norm() > bound_m ||
      Eigen::AngleAxisd(correction.linear()).angle() > bound_rad) {
    ++stats_.scans_untracked;
    return predicted;
  }
  untracked_sweeps_ = 0;
  ++stats_.scans_tracked;
  track_T_last_base_ = result->T_target_source;
  return track_T_last_base_;
}

}  // namespace msgraphs::core
