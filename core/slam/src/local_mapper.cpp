// SPDX-License-Identifier: MIT
#include "msgraphs/core/slam/local_mapper.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>

#include "msgraphs/base/assert.hpp"
#include "msgraphs/core/geometry/se3.hpp"
#include "msgraphs/core/perception/deskew.hpp"

namespace msgraphs::core {

const char* ToString(MapperStage stage) {
  switch (stage) {
    case MapperStage::kPreprocess:
      return "preprocess";
    case MapperStage::kScanMatching:
      return "scan matching";
    case MapperStage::kPlanes:
      return "planes";
    case MapperStage::kFreeSpace:
      return "free space";
    case MapperStage::kLocalSolve:
      return "local solve";
    case MapperStage::kLoopClosure:
      return "loop closure";
    case MapperStage::kFullSolve:
      return "full solve";
    case MapperStage::kRooms:
      return "rooms";
    case MapperStage::kCount:
      break;
  }
  return "?";
}

Status LocalMapperConfig::Validate() const {
  if (!IsValidRigidTransform(T_base_lidar, 1e-6))
    return Error{Errc::kInvalidConfig, "mapper: T_base_lidar not rigid"};
  if (!(keyframe_spacing_m > 0) || !(keyframe_angle_rad > 0) || !(voxel_m > 0) ||
      !(store_voxel_m >= voxel_m) || !(min_range_m >= 0) || !(max_range_m > min_range_m) ||
      max_scan_points < 100 || local_map_keyframes < 1 || !(local_map_resolution_m > 0) ||
      !(scan_match_sigma_m > 0) || !(scan_match_max_fitness_m2 > 0) ||
      !(scan_match_min_overlap > 0 && scan_match_min_overlap <= 1) || !(max_correction_m > 0) ||
      !(max_correction_rad > 0) || !(odometry_sigma_min_m > 0) ||
      !(odometry_rotation_sigma_min > 0) || !(odometry_sigma_per_m >= 0) ||
      !(odometry_rotation_sigma_per_m >= 0) || !(odometry_gap_inflation >= 1) ||
      !(odometry_gate_chi2 >= 0) || !(motion_seed_max_age_s >= 0) ||
      (track_scans && !(tracking_voxel_m >= voxel_m)) || !(tracking_prior_sigma_m > 0) ||
      !(tracking_prior_sigma_rad > 0) ||
      room_update_every_keyframes < 1 || full_solve_every_keyframes < 1 || max_plane_priors < 1 ||
      cloud_store_points < max_scan_points || odometry_capacity < 16 || !(odometry_max_gap_s > 0)) {
    return Error{Errc::kInvalidConfig,
                 "mapper: spacing, voxels, ranges, sigmas and capacities must be positive"};
  }
  // A loop waits up to twice the lag for its judgement; its keyframes must still be in the
  // local window then, never sparsified.
  if (2 * full_solve_lag_keyframes >= graph.local_window_keyframes) {
    return Error{Errc::kInvalidConfig,
                 "mapper: full_solve_lag_keyframes must be below half the graph's local window"};
  }
  for (const Status& s :
       {graph.Validate(), planes.Validate(), association.Validate(), rooms.Validate(),
        grid.Validate(), loops.Validate(), scan_matching.Validate(),
        scan_match_fitness_gate().Validate()}) {
    if (!s) return s;
  }
  return Ok();
}

FitnessGateConfig LocalMapperConfig::scan_match_fitness_gate() const {
  FitnessGateConfig gate;
  gate.floor_m2 = scan_match_max_fitness_m2;
  gate.window = scan_match_fitness_window;
  gate.outlier_z = scan_match_fitness_outlier_z;
  return gate;
}

LocalMapper::~LocalMapper() {
  if (full_job_.pending()) graph_.DropFullSolve(full_job_);  // waits for a worker running it
}

Status LocalMapper::Init(const LocalMapperConfig& config) {
  if (auto s = config.Validate(); !s) return s;
  if (full_job_.pending()) graph_.DropFullSolve(full_job_);  // it borrows the graph's costs
  snapshot_state_ = SnapshotState::kNone;  // its buffer belongs to the state Init forgets
  snapshot_out_ = {};
  config_ = config;
  if (auto s = graph_.Init(config.graph); !s) return s;
  if (auto s = full_job_.Init(config.graph); !s) return s;
  pending_loops_.Init(kLoopChecks);
  job_loops_.Init(kLoopChecks);
  keyframe_count_ = full_apply_at_ = 0;
  full_wanted_ = false;
  if (auto s = fitness_gate_.Init(config.scan_match_fitness_gate()); !s) return s;
  odometry_.Init(config.odometry_capacity, config.odometry_max_gap_s);
  const std::size_t slots = config.graph.max_keyframes + 1;
  // A full store makes room for a sixteenth of itself at a time: the slide that follows (one
  // memmove of what is stored) is then paid once per that many points, about 15 keyframes at
  // the default size, not at every keyframe.
  clouds_.Init(slots, config.cloud_store_points, config.cloud_store_points / 16);
  cover_.Init(slots, config.local_map_keyframes, config.keyframe_spacing_m, config.max_range_m);
  PlaneAssociationConfig association = config.association;
  association.sensor_height_m = config.T_base_lidar.translation().z();  // keyframes are base frames
  if (auto s = planes_mapper_.Init(config.graph.max_planes, association); !s) return s;
  if (auto s = rooms_.Init(config.grid, 1024, config.graph.max_rooms, config.rooms); !s) return s;
  if (auto s = loops_.Init(slots, config.max_scan_points, config.loops); !s) return s;
  if (auto s = grid_.Init(config.grid); !s) return s;
  const std::size_t n = config.max_scan_points;
  const std::size_t local_n = n * 2;  // the local map, after downsampling
  extractor_.Init(n);
  voxel_.Init(std::max(n, config.local_map_keyframes * n));
  scan_voxel_.Init(n);
  tree_.Init(n);
  local_tree_.Init(local_n);
  local_map_.Init(local_n);
  vgicp_.Init(n);
  for (auto* b : {&work_, &filtered_, &down_, &normals_, &stored_, &world_points_, &track_down_,
                  &track_normals_})
    b->Init(n);
  track_covariances_.Init(n);
  track_tree_.Init(n);
  have_track_ = false;
  local_map_keyframe_ = local_map_failed_ = kNoKeyframe;
  prepared_ = false;
  untracked_sweeps_ = 0;
  keyframe_motion_ = {};
  local_raw_.Init(config.local_map_keyframes * n);
  local_points_.Init(local_n);
  local_normals_.Init(local_n);
  covariances_.Init(n);
  local_covariances_.Init(local_n);
  times_.Init(n);
  planes_.Init(config.planes.max_planes);
  sequence_.assign(slots, 0);
  keyframe_odometry_.assign(slots, Eigen::Isometry3d::Identity());
  recent_.assign(config.local_map_keyframes, 0);
  deskew_poses_.fill(Eigen::Isometry3d::Identity());
  nearby_.assign(slots, {0.0, 0u});
  recent_scratch_.assign(slots, 0);
  prior_factors_.Init(config.max_plane_priors);
  floor_members_.Init(config.max_scan_points);
  next_sequence_ = 1;
  have_keyframe_ = false;
  motion_m_ = motion_s_ = motion_end_s_ = 0;
  T_map_odom_ = Eigen::Isometry3d::Identity();
  path_m_ = 0;
  keyframes_since_rooms_ = keyframes_since_full_ = 0;
  stats_ = {};
  return Ok();
}

Status LocalMapper::AddOdometry(double stamp_s, const Eigen::Isometry3d& T_odom_base) {
  return odometry_.Add(stamp_s, T_odom_base);
}

Matrix6d LocalMapper::OdometryInformation(const Eigen::Isometry3d& delta, bool across_gap) const {
  const double distance = delta.translation().norm();
  double sigma_t = std::max(config_.odometry_sigma_min_m, config_.odometry_sigma_per_m * distance);
  double sigma_r = std::max(config_.odometry_rotation_sigma_min,
                            config_.odometry_rotation_sigma_per_m * distance);
  if (across_gap) {
    sigma_t *= config_.odometry_gap_inflation;
    sigma_r *= config_.odometry_gap_inflation;
  }
  Matrix6d information = Matrix6d::Zero();
  information.diagonal() << Eigen::Vector3d::Constant(1.0 / (sigma_t * sigma_t)),
      Eigen::Vector3d::Constant(1.0 / (sigma_r * sigma_r));
  return information;
}

bool LocalMapper::Preprocess(const LidarScanView& scan,
                             const Eigen::Isometry3d& T_odom_start,
                             const Eigen::Isometry3d& T_odom_end, bool buffered) {
  if (!prepared_) PrepareSweep(scan, T_odom_start, T_odom_end, buffered);
  prepared_ = false;
  if (!scan_voxel_.Downsample(filtered_.span(), config_.voxel_m, down_) || down_.size() < 100)
    return false;
  if (!tree_.Build(down_.span())) return false;
  const Eigen::Vector3f viewpoint = config_.T_base_lidar.translation().cast<float>();
  if (!EstimateCovariances(down_.span(), tree_, {}, normals_, covariances_, &viewpoint))
    return false;
  return true;
}

void LocalMapper::PrepareSweep(const LidarScanView& scan, const Eigen::Isometry3d& T_odom_start,
                               const Eigen::Isometry3d& T_odom_end, bool buffered) {
  work_.clear();
  times_.clear();
  for (std::size_t i = 0; i < scan.points_lidar.size(); ++i) {
    if (!work_.try_push_back(scan.points_lidar[i])) {
      stats_.scan_points_beyond_capacity += scan.points_lidar.size() - i;
      break;
    }
    static_cast<void>(times_.try_push_back(scan.time_offset_s[i]));
  }
  // Deskew to the end of the sweep with the odometry's motion in the lidar frame, sampled
  // across the sweep (a legged robot's body rocks within one sweep: deskew.hpp); where the
  // odometry cannot say (a lookup fails), constant velocity from start to end.
  const double duration_s = std::max(1e-3, scan.end_s - scan.start_s);
  const Eigen::Isometry3d T_end_lidar_inv = (T_odom_end * config_.T_base_lidar).inverse();
  bool sampled = buffered;
  for (std::size_t k = 0; k < deskew_poses_.size() && sampled; ++k) {
    const double t = scan.start_s + duration_s * static_cast<double>(k) /
                                        static_cast<double>(deskew_poses_.size() - 1);
    const auto at = k + 1 == deskew_poses_.size() ? odometry_.At(scan.end_s) : odometry_.At(t);
    sampled = at.has_value();
    if (sampled) deskew_poses_[k] = T_end_lidar_inv * at->T_odom_base * config_.T_base_lidar;
  }
  if (sampled) {
    static_cast<void>(DeskewToEnd(work_.span(), times_.span(), duration_s,
                                  std::span<const Eigen::Isometry3d>(deskew_poses_)));
  } else {
    const Eigen::Isometry3d T_start_end = (T_odom_start * config_.T_base_lidar).inverse() *
                                          (T_odom_end * config_.T_base_lidar);
    static_cast<void>(DeskewToEnd(work_.span(), times_.span(), duration_s, T_start_end));
  }
  RangeFilter(work_.span(), config_.min_range_m, config_.max_range_m, filtered_);
  const Eigen::Affine3f T_base_lidar = config_.T_base_lidar.cast<float>();
  for (Eigen::Vector3f& p : filtered_) p = T_base_lidar * p;
}

// The last keyframes' stored clouds in the frame of keyframe `last`, downsampled, with their
// own covariances (from the union, which is denser than any one keyframe).
bool LocalMapper::BuildLocalMap(std::uint32_t last) {
  const std::size_t count = graph_.RecentKeyframes(std::span(recent_));
  return BuildMapFrom(last, std::span<const std::uint32_t>(recent_.data(), count));
}

// The clouds of `keyframes` (in that order, until local_raw_ is full) in the frame of `last`.
bool LocalMapper::BuildMapFrom(std::uint32_t last, std::span<const std::uint32_t> keyframes) {
  local_map_keyframe_ = kNoKeyframe;  // EnsureLocalMap says which keyframe's it is
  const Eigen::Isometry3d T_last_map = graph_.keyframe_pose(last).inverse();
  local_raw_.clear();
  for (const std::uint32_t k : keyframes) {
    const auto cloud = clouds_.Get(k, sequence_[k]);
    const Eigen::Affine3f T = (T_last_map * graph_.keyframe_pose(k)).cast<float>();
    for (const Eigen::Vector3f& p : cloud) {
      if (!local_raw_.try_push_back(T * p)) break;
    }
  }
  if (!voxel_.Downsample(local_raw_.span(), config_.store_voxel_m, local_points_) ||
      local_points_.size() < 100) {
    return false;
  }
  stats_.local_map_points_peak = std::max(stats_.local_map_points_peak, local_points_.size());
  if (!local_tree_.Build(local_points_.span())) return false;
  if (!EstimateCovariances(local_points_.span(), local_tree_, {}, local_normals_,
                           local_covariances_))
    return false;
  return static_cast<bool>(local_map_.Build(local_points_.span(), local_covariances_.span(),
                                            config_.local_map_resolution_m));
}

Expected<ScanOutcome> LocalMapper::AddScan(const LidarScanView& scan, StageObserver* observer) {
  return AddScanImpl(scan, observer, nullptr);
}

Expected<ScanOutcome> LocalMapper::ReplayKeyframe(const LidarScanView& scan,
                                                  const KeyframeMotion& motion) {
  if (!IsValidRigidTransform(motion.T_last_new, 1e-6))
    return Error{Errc::kInvalidArgument, "replay: the keyframe's motion is not a rigid transform"};
  return AddScanImpl(scan, nullptr, &motion);
}

Expected<ScanOutcome> LocalMapper::AddScanImpl(const LidarScanView& scan, StageObserver* observer,
                                               const KeyframeMotion* replay) {
  ++stats_.scans;
  prepared_ = false;
  if (scan.points_lidar.size() != scan.time_offset_s.size() || !std::isfinite(scan.start_s) ||
      !std::isfinite(scan.end_s) || scan.end_s < scan.start_s) {
    ++stats_.bad_scans;
    return Error{Errc::kInvalidArgument, "scan: points and times differ in length, or bad stamps"};
  }
  const auto at_end = odometry_.At(scan.end_s);
  const auto at_start = odometry_.At(scan.start_s);
  if (!at_end || !at_start) {
    ++stats_.no_odometry;
    return ScanOutcome::kNoOdometry;
  }
  const Eigen::Isometry3d T_odom_now = at_end->T_odom_base;
  const Eigen::Isometry3d delta = last_odometry_.inverse() * T_odom_now;
  const bool across_gap = at_end->across_gap || at_start->across_gap;
  // The motion since the last keyframe: tracked sweep by sweep, or the encoders'.
  Eigen::Isometry3d motion = delta;
  bool tracked = false;
  if (replay != nullptr) {
    // As the live run made it: no tracking, no spacing test.
    motion = replay->T_last_new;
    tracked = replay->tracked;
  } else if (have_keyframe_ && config_.track_scans) {
    const std::uint64_t before = stats_.scans_tracked;
    motion = Track(scan, at_start->T_odom_base, T_odom_now, across_gap);
    tracked = stats_.scans_tracked > before;
    T_map_odom_ = graph_.keyframe_pose(last_keyframe_) * motion * T_odom_now.inverse();
  }
  if (have_keyframe_ && replay == nullptr) {
    const double angle = Eigen::AngleAxisd(motion.linear()).angle();
    if (motion.translation().norm() < config_.keyframe_spacing_m &&
        angle < config_.keyframe_angle_rad) {
      return ScanOutcome::kNotKeyframe;
    }
    if (!(scan.end_s > graph_.keyframe_stamp(last_keyframe_))) return ScanOutcome::kNotKeyframe;
  }
  // ---- a keyframe ----
  if (observer != nullptr) observer->KeyframeStarted();
  if (!Preprocess(scan, at_start->T_odom_base, T_odom_now, true)) {
    ++stats_.bad_scans;
    return Error{Errc::kDegenerate, "keyframe scan has too few usable points"};
  }
  Stage(observer, MapperStage::kPreprocess);
  Eigen::Isometry3d T_map_new = T_map_odom_ * T_odom_now;
  bool matched = false;
  Eigen::Isometry3d T_last_new = motion;
  Matrix6d match_information = Matrix6d::Identity();
  last_match_ = {};
  if (have_keyframe_ && EnsureLocalMap()) {
    fitness_limit_m2_ = fitness_gate_.Limit();
    stats_.scan_match_fitness_limit_m2 = fitness_limit_m2_;
    double fitness_m2 = 0;
    // Seeded by the tracked motion (or the encoders'), which also holds the directions the
    // clouds leave free (VgicpPrior): along a corridor the match does not slide on noise.
    VgicpPrior motion_prior;
    motion_prior.T_target_source = motion;
    motion_prior.information = HoldingPrior(delta, across_gap);
    motion_prior.clouds_sigma_m = config_.scan_match_sigma_m;
    MatchOutcome outcome =
        MatchFrom(motion, T_last_new, match_information, fitness_m2, &motion_prior);
    // A step whose odometry disagrees with the pace the last match measured may be a slip:
    // VGICP from a guess 0.4 m off can stop part way and still pass every test, so the motion's
    // guess is registered too, and the better fit of the two accepted ones kept.
    Eigen::Isometry3d seed, T_motion;
    Matrix6d motion_information;
    double motion_fitness_m2 = 0;
    if (!tracked && MotionSeed(delta, scan.end_s, seed) &&
        MatchFrom(seed, T_motion, motion_information, motion_fitness_m2) == MatchOutcome::kAccepted &&
        (outcome != MatchOutcome::kAccepted || motion_fitness_m2 < fitness_m2)) {
      if (outcome == MatchOutcome::kAccepted) ++stats_.scan_match_motion_preferred;
      ++stats_.scan_match_motion_seeded;
      outcome = MatchOutcome::kAccepted;
      T_last_new = T_motion;
      match_information = motion_information;
      fitness_m2 = motion_fitness_m2;
      last_match_.motion_seeded = true;
    }
    last_match_.attempted = true;
    last_match_.from_s = graph_.keyframe_stamp(last_keyframe_);
    last_match_.to_s = scan.end_s;
    last_match_.fitness_m2 = fitness_m2;
    last_match_.limit_m2 = fitness_limit_m2_;
    last_match_.T_from_to = T_last_new;
    switch (outcome) {
      case MatchOutcome::kAccepted:
        matched = true;
        if (fitness_m2 > config_.scan_match_max_fitness_m2) ++stats_.scan_match_above_floor;
        T_map_new = graph_.keyframe_pose(last_keyframe_) * T_last_new;
        ++stats_.scan_match_accepted;
        break;
      case MatchOutcome::kFailed: ++stats_.scan_match_rejected_failed; break;
      case MatchOutcome::kFitness: ++stats_.scan_match_rejected_fitness; break;
      case MatchOutcome::kOverlap: ++stats_.scan_match_rejected_overlap; break;
      case MatchOutcome::kDiverged: ++stats_.scan_match_rejected_diverged; break;
    }
    last_match_.result = ToString(outcome);
    // The gate learns from every converged match it judged, refused ones too: a sensor or a
    // building whose every fitness is above the floor would otherwise never be matched at all.
    if (outcome == MatchOutcome::kAccepted || outcome == MatchOutcome::kFitness)
      fitness_gate_.Add(fitness_m2);
  } else if (have_keyframe_) {
    ++stats_.scan_match_rejected_failed;
  }
  Stage(observer, MapperStage::kScanMatching);
  if (have_keyframe_ && !matched) T_map_new = graph_.keyframe_pose(last_keyframe_) * motion;
  auto added = graph_.AddKeyframe(scan.end_s, T_map_new);
  if (!added) {
    ++stats_.keyframes_refused;
    return added.error();
  }
  const std::uint32_t id = *added;
  // The graph hands out ids below its store (max_keyframes + 1), which sizes ours too.
  MSGRAPHS_ASSERT(id < sequence_.size() && id < keyframe_odometry_.size(),
                  "keyframe id beyond the mapper's per-keyframe stores");
  sequence_[id] = next_sequence_++;
  keyframe_odometry_[id] = T_odom_now;
  if (have_keyframe_) {
    if (across_gap) ++stats_.odometry_gap_keyframes;
    Matrix6d odometry_information = OdometryInformation(delta, across_gap);
    if (matched && config_.odometry_gate_chi2 > 0) {
      // The slip gate: the two measurements of this step against their combined covariance.
      const Eigen::Isometry3d disagreement = delta.inverse() * T_last_new;
      const Eigen::AngleAxisd turn(disagreement.linear());
      Eigen::Matrix<double, 6, 1> e;
      e << disagreement.translation(), turn.angle() * turn.axis();
      const Matrix6d covariance = odometry_information.inverse() + match_information.inverse();
      const double d2 = e.dot(covariance.ldlt().solve(e));
      if (std::isfinite(d2) && d2 > config_.odometry_gate_chi2) {
        odometry_information *= 6.0 / d2;  // the disagreement at its expectation, 6 dof
        ++stats_.odometry_slips;
      }
    }
    if (!graph_.AddRelativePose(last_keyframe_, id, delta, odometry_information,
                                RelativePoseKind::kOdometry)) {
      ++stats_.chain_factors_refused;
    }
    if (matched && !graph_.AddRelativePose(last_keyframe_, id, T_last_new, match_information,
                                           RelativePoseKind::kScanMatch)) {
      ++stats_.chain_factors_refused;
    }
    path_m_ += delta.translation().norm();
  }
  // Planes.
  ExtractPlanes(id);
  static_cast<void>(planes_mapper_.Associate(graph_, id, planes_.span()));
  Stage(observer, MapperStage::kPlanes);
  // Stored cloud and descriptor.
  if (scan_voxel_.Downsample(down_.span(), config_.store_voxel_m, stored_)) {
    cover_.Bind(clouds_, graph_, sequence_, id);  // bound here: a mapper may be moved after Init
    static_cast<void>(clouds_.Put(id, sequence_[id], stored_.span(), &cover_));
    static_cast<void>(loops_.AddKeyframe(id, sequence_[id], path_m_, stored_.span()));
  }
  // Free space from the full-resolution sweep, with the estimate as it is now.
  {
    const Eigen::Isometry3d T_map_base = graph_.keyframe_pose(id);
    const Eigen::Affine3f T = T_map_base.cast<float>();
    world_points_.clear();
    for (const Eigen::Vector3f& p : filtered_)
      static_cast<void>(world_points_.try_push_back(T * p));
    const Eigen::Vector3f sensor_map = (T_map_base * config_.T_base_lidar).translation().cast<float>();
    if (config_.grid_follows_robot) static_cast<void>(grid_.Follow(sensor_map.head<2>()));
    grid_.Integrate(sensor_map,
                    world_points_.span(),
                    static_cast<float>(T_map_base.translation().z() - config_.base_height_m));
  }
  Stage(observer, MapperStage::kFreeSpace);
  static_cast<void>(graph_.Solve(SolveKind::kLocal));
  Stage(observer, MapperStage::kLocalSolve);
  const auto store = [this](std::uint32_t k, std::uint64_t s) { return clouds_.Get(k, s); };
  const bool loop = loops_.Detect(graph_, id, down_.span(), covariances_.span(), store);
  Stage(observer, MapperStage::kLoopClosure);
  ScheduleFullSolve(loop);
  Stage(observer, MapperStage::kFullSolve);
  if (++keyframes_since_rooms_ >= config_.room_update_every_keyframes) {
    keyframes_since_rooms_ = 0;
    static_cast<void>(rooms_.Update(grid_, planes_mapper_, graph_));
  }
  Stage(observer, MapperStage::kRooms);
  if (matched) {
    motion_m_ = T_last_new.translation().norm();
    motion_s_ = scan.end_s - graph_.keyframe_stamp(last_keyframe_);
    motion_end_s_ = scan.end_s;
  }
  keyframe_motion_.T_last_new = motion;
  keyframe_motion_.tracked = tracked;
  have_keyframe_ = true;
  last_keyframe_ = id;
  last_odometry_ = T_odom_now;
  T_map_odom_ = graph_.keyframe_pose(id) * T_odom_now.inverse();
  // Tracking restarts at the new keyframe, against its local map (built now, for the sweeps
  // until the next keyframe and that keyframe's match).
  have_track_ = true;
  track_T_last_base_ = Eigen::Isometry3d::Identity();
  track_T_odom_ = T_odom_now;
  untracked_sweeps_ = 0;
  if (config_.track_scans) static_cast<void>(EnsureLocalMap());
  ++stats_.keyframes;
  EndKeyframe();
  return ScanOutcome::kKeyframe;
}

const char* LocalMapper::ToString(MatchOutcome outcome) {
  switch (outcome) {
    case MatchOutcome::kAccepted: return "accepted";
    case MatchOutcome::kFailed: return "failed";
    case MatchOutcome::kFitness: return "fitness";
    case MatchOutcome::kOverlap: return "overlap";
    case MatchOutcome::kDiverged: return "diverged";
  }
  return "none";
}

LocalMapper::MatchOutcome LocalMapper::MatchFrom(const Eigen::Isometry3d& T_last_seed,
                                                 Eigen::Isometry3d& T_last_new,
                                                 Matrix6d& information, double& fitness_m2,
                                                 const VgicpPrior* prior) {
  auto result = vgicp_.Align(down_.span(), covariances_.span(), local_map_, local_points_.span(),
                             local_tree_, T_last_seed, config_.scan_matching, nullptr, prior);
  if (!result || !result->converged) return MatchOutcome::kFailed;
  fitness_m2 = result->fitness;
  if (result->fitness > fitness_limit_m2_) return MatchOutcome::kFitness;
  if (static_cast<double>(result->correspondences) <
      config_.scan_match_min_overlap * static_cast<double>(down_.size())) {
    return MatchOutcome::kOverlap;
  }
  const Eigen::Isometry3d correction = T_last_seed.inverse() * result->T_target_source;
  if (correction.translation().norm() > config_.max_correction_m ||
      Eigen::AngleAxisd(correction.linear()).angle() > config_.max_correction_rad) {
    return MatchOutcome::kDiverged;
  }
  T_last_new = result->T_target_source;
  information = InformationFromHessian(result->hessian, config_.scan_match_sigma_m);
  return MatchOutcome::kAccepted;
}

bool LocalMapper::MotionSeed(const Eigen::Isometry3d& delta, double end_s,
                             Eigen::Isometry3d& seed) const {
  if (!(config_.motion_seed_max_age_s > 0) || !(motion_s_ > 0) ||
      !(end_s - motion_end_s_ <= config_.motion_seed_max_age_s)) {
    return false;
  }
  const double step_s = end_s - graph_.keyframe_stamp(last_keyframe_);
  const double along_m = motion_m_ / motion_s_ * step_s;
  const double odometry_m = delta.translation().norm();
  // The odometry's direction (it turns with the robot); a step it saw as nothing has none,
  // and then no seed of ours is better than its guess.
  if (!(odometry_m > 0.1 * config_.keyframe_spacing_m) || !std::isfinite(along_m)) return false;
  seed = delta;
  seed.translation() = delta.translation() * (along_m / odometry_m);
  // The same guess as the odometry's is no second attempt.
  return (seed.translation() - delta.translation()).norm() > 0.5 * config_.max_correction_m;
}

void LocalMapper::ExtractPlanes(std::uint32_t keyframe) {
  // Heights along gravity as the estimate has it (the map's z in the keyframe frame).
  const Eigen::Vector3d up_kf = graph_.keyframe_pose(keyframe).linear().row(2).transpose();
  static_cast<void>(extractor_.Extract(down_.span(), normals_.span(), config_.planes, planes_, up_kf));
  // Did the general search find the floor under the robot (base frame: z = -base_height_m)?
  for (const ExtractedPlane& p : planes_) {
    if (p.kind == PlaneKind::kHorizontal && p.normal.z() > 0 &&
        std::fabs(p.d - config_.base_height_m) <= config_.floor_band_m) {
      return;
    }
  }
  // If not, look for it where it must be: the far floor rings are too sparse for the point
  // normals the general search relies on (clutter hides the near ones).
  floor_members_.clear();
  const auto floor_z = static_cast<float>(-config_.base_height_m);
  for (std::uint32_t i = 0; i < down_.size(); ++i) {
    // Loose on the normal (sparse rings make it noisy) but not on walls: their bottom strip is
    // in the band too, and would tilt the fit towards them.
    if (std::fabs(down_[i].z() - floor_z) <= static_cast<float>(config_.floor_band_m) &&
        std::fabs(normals_[i].z()) >= static_cast<float>(config_.floor_min_normal_z))
      static_cast<void>(floor_members_.try_push_back(i));
  }
  ExtractedPlane floor;
  if (floor_members_.size() < config_.floor_min_points ||
      !extractor_.Fit(down_.span(), floor_members_.span(), config_.planes, floor)) {
    return;
  }
  // Once more with the points near the fitted plane (drops kerbs and debris in the band).
  const Eigen::Vector3f n = floor.normal.cast<float>();
  const auto d = static_cast<float>(floor.d);
  std::size_t kept = 0;
  for (std::uint32_t i : floor_members_) {
    if (std::fabs(n.dot(down_[i]) + d) <= static_cast<float>(config_.floor_fit_band_m))
      floor_members_[kept++] = i;
  }
  floor_members_.resize_down(kept);
  if (kept < config_.floor_min_points ||
      !extractor_.Fit(down_.span(), floor_members_.span(), config_.planes, floor) ||
      floor.normal.z() < std::cos(config_.floor_max_tilt_deg * 3.14159265358979 / 180.0)) {
    return;
  }
  floor.kind = PlaneKind::kHorizontal;
  if (!planes_.try_push_back(floor)) planes_[planes_.size() - 1] = floor;  // the floor matters most
  ++stats_.floors_found;
}

Status LocalMapper::SetPlanePriors(std::span<const PlanePrior> priors) {
  for (std::uint32_t id : prior_factors_) static_cast<void>(graph_.RemoveFactor(id));
  prior_factors_.clear();
  for (const PlanePrior& prior : priors) {
    if (prior_factors_.full()) {
      ++stats_.plane_priors_refused;
      continue;
    }
    auto id = graph_.AddPlanePrior(prior);
    if (!id) {
      ++stats_.plane_priors_refused;
      continue;
    }
    prior_factors_.push_back(*id);
  }
  stats_.plane_priors = prior_factors_.size();
  keyframes_since_full_ = config_.full_solve_every_keyframes;  // a full solve at the next keyframe
  return Ok();
}

Status LocalMapper::Finish() {
  if (!have_keyframe_) return Ok();
  if (full_job_.pending()) ApplyBackgroundSolve();
  static_cast<void>(rooms_.Update(grid_, planes_mapper_, graph_));
  auto report = graph_.Solve(SolveKind::kFull);
  if (!report) return report.error();
  ++stats_.full_solves;
  // Loop closures no background solve has judged yet: this one does.
  bool refused = false;
  for (std::uint32_t f : pending_loops_) {
    const bool out = loops_.RejectIfContradicted(graph_, f, nullptr);
    refused = refused || out;
    if (!out) ++stats_.loop_closures;
  }
  pending_loops_.clear();
  if (refused) {
    report = graph_.Solve(SolveKind::kFull);  // undo their pull
    if (!report) return report.error();
    ++stats_.full_solves;
  }
  // The solve moved the keyframes the local map was built from.
  local_map_keyframe_ = local_map_failed_ = kNoKeyframe;
  T_map_odom_ = have_track_ ? graph_.keyframe_pose(last_keyframe_) * track_T_last_base_ * track_T_odom_.inverse()
                            : graph_.keyframe_pose(last_keyframe_) * last_odometry_.inverse();
  return Ok();
}

}  // namespace msgraphs::core
