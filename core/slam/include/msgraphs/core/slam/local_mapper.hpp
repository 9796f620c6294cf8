// SPDX-License-Identifier: MIT
// The local S-Graph front end of one robot: scans and encoder odometry in, the four-layer graph
// out (docs/s-graph.md).
//
// Per scan: odometry at the scan's start and end (OdometryBuffer); with track_scans (the
// default), the sweep deskewed, thinned to tracking_voxel_m and tracked by VGICP against the
// local map, seeded by the encoders (a few ms); a keyframe when the robot moved
// keyframe_spacing_m or turned keyframe_angle_rad since the last one. Without tracking, other
// scans cost two odometry lookups and nothing else.
// Per keyframe: deskew with the odometry's motion, range filter, base frame, 0.1 m voxels,
// normals and covariances; VGICP against the local map (the last keyframes' clouds in the last
// keyframe's frame) seeded by odometry, checked (convergence, fitness, overlap, divergence from
// the odometry) and added as a scan-matching factor beside the encoder factor; planes extracted
// and associated (PlaneMapper); free space integrated; a bounded local solve; loop-closure
// search (LoopCloser) and a full solve after one; rooms and the floor every few keyframes
// (RoomMapper).
//
// Core has no clock: an optional StageObserver, given by the caller, is told when each stage
// ends, so tools measure per-stage times. Every buffer is sized at Init; the per-scan path
// allocates nothing (LocalMapper.BadScansAreCountedAndTheScanPathDoesNotAllocate). A keyframe
// allocates: Ceres's factor storage and solver workspace (bounded by the graph's capacities).
// The keyframe stages' own buffers do not: preprocessing (Perception.*AllocateNothing*), plane
// extraction (Planes.ExtractionAllocatesNothingPerKeyframe), VGICP (Vgicp.RecoversAKnownTransform),
// the cloud store, free space and rooms (Rooms.SegmentingAndDetectingAllocateNothing).
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "msgraphs/base/bounded_vector.hpp"
#include "msgraphs/base/expected.hpp"
#include "msgraphs/base/snapshot_header.hpp"
#include "msgraphs/core/graph/s_graph.hpp"
#include "msgraphs/core/graph/s_graph_solve_job.hpp"
#include "msgraphs/core/perception/covariances.hpp"
#include "msgraphs/core/perception/free_space_grid.hpp"
#include "msgraphs/core/perception/kdtree.hpp"
#include "msgraphs/core/perception/plane_extraction.hpp"
#include "msgraphs/core/perception/voxel_grid.hpp"
#include "msgraphs/core/registration/gaussian_voxel_map.hpp"
#include "msgraphs/core/registration/vgicp.hpp"
#include "msgraphs/core/slam/cloud_cover_policy.hpp"
#include "msgraphs/core/slam/keyframe_cloud_store.hpp"
#include "msgraphs/core/slam/loop_closer.hpp"
#include "msgraphs/core/slam/fitness_gate.hpp"
#include "msgraphs/core/slam/odometry_buffer.hpp"
#include "msgraphs/core/slam/plane_mapper.hpp"
#include "msgraphs/core/slam/room_mapper.hpp"

namespace msgraphs::core {

struct LocalMapperConfig {
  Eigen::Isometry3d T_base_lidar = Eigen::Isometry3d(Eigen::Translation3d(0, 0, 0.30));
  double base_height_m = 0.5;  ///< base frame above the floor (Spot walking)
  /// When the general plane search misses the floor under a legged robot (far floor rings are
  /// too sparse for the point normals it needs, and clutter hides the near ones), it is looked
  /// for where it must be: points within floor_band_m of base_height_m below the base, refitted
  /// once and kept within floor_fit_band_m, at least floor_min_points, tilted at most
  /// floor_max_tilt_deg.
  double floor_band_m = 0.12, floor_fit_band_m = 0.05, floor_max_tilt_deg = 3.0;
  double floor_min_normal_z = 0.7;  ///< a floor point's normal is at most 45 degrees off vertical
  std::size_t floor_min_points = 150;
  double keyframe_spacing_m = 1.0;
  double keyframe_angle_rad = 0.35;
  float min_range_m = 0.5f, max_range_m = 25.0f;
  float voxel_m = 0.1f;        ///< the keyframe cloud: planes and the scan-matching source
  float store_voxel_m = 0.2f;  ///< stored clouds: local map and loop-closure targets
  std::size_t max_scan_points = 60000;
  std::size_t local_map_keyframes = 10;
  double local_map_resolution_m = 0.4;  ///< VGICP voxels of the local map
  double scan_match_sigma_m = 0.02;     ///< strongest direction; the Hessian gives the rest
  /// The fitness limit (and relocalisation's). With scan_match_fitness_outlier_z > 0 it is a
  /// floor, widened to the upper outlier bound of the robot's own last
  /// scan_match_fitness_window match fitnesses (FitnessGate; 3.5 is the modified z-score rule's
  /// value). Off by default: on the benchmark it rescued slipped steps but let through as many
  /// matches 6-20 cm off, and the maps came out worse at the median (docs/s-graph.md, "Fitness
  /// gate"). A robot whose every fit is above the limit (a noisier sensor) turns it on.
  double scan_match_max_fitness_m2 = 0.05;
  std::size_t scan_match_fitness_window = 100;
  double scan_match_fitness_outlier_z = 0.0;
  double scan_match_min_overlap = 0.5;
  double max_correction_m = 0.25;   ///< scan matching may move the odometry's guess this much
  double max_correction_rad = 0.1;  ///< ...and turn it this much, else it diverged
  /// A foot that slips misreports a whole step: in the benchmark's slips the encoders gave 53 %
  /// to 147 % of 1-2 m, 0.3-0.7 m off at one keyframe, beyond max_correction_m (or VGICP from
  /// that far stopped part way), and that one step left the robot's own map 20-30 cm off.
  /// When the odometry's step disagrees with the pace the last accepted match measured (its
  /// speed along the odometry's direction, over this step's time) by more than half
  /// max_correction_m, the scan is registered from that guess too, held to the same tests
  /// against it, and the better fit kept; the slip gate then weakens the step's odometry.
  /// The last match's motion stands for the robot's for this long (a walking robot keeps its
  /// pace over a stride or two; after a few unmatched seconds it says no more than the
  /// encoders). 0: off.
  double motion_seed_max_age_s = 3.0;
  /// Scan tracking: every sweep, not only keyframes, is registered against the local map (a
  /// coarse copy of it, tracking_voxel_m), seeded by the encoders' motion since the previous
  /// sweep. A foot that slips misreports a step by up to half its length; between two sweeps
  /// (0.1 s) that is centimetres, well inside VGICP's reach, where between two keyframes it
  /// was 0.3-0.7 m. The keyframe's match is then seeded by the tracked motion, and keyframes
  /// are spaced by it. The prior holds what the clouds do not constrain (along a corridor) at
  /// the encoders' step, never tighter than tracking_prior_sigma_m / _rad: within one sweep a
  /// slip puts the encoders up to 5 cm off (half a step at 1 m/s), which the clouds must be
  /// able to correct wherever they constrain anything. Off: keyframes only, seeded by the
  /// encoders and the last match's pace (motion_seed_max_age_s).
  bool track_scans = true;
  float tracking_voxel_m = 0.25f;  ///< a few thousand points: a few ms a sweep
  double tracking_prior_sigma_m = 0.05, tracking_prior_sigma_rad = 0.01;
  /// Encoder odometry factor: sigma grows with the motion. Configuration values from the
  /// robot's odometry, not fitted: 3 % of the distance (a legged robot's encoders: 1-2 % scale
  /// error, twice that as margin) and 0.005 rad a metre (0.3 degrees, about three times the
  /// drift of 1 degree per 10 m Spot's state estimate is quoted at); the floors are the
  /// encoders' resolution. A robot with other odometry sets its own (the node's [odometry] keys); slips
  /// beyond them are caught by the slip gate below.
  double odometry_sigma_per_m = 0.03, odometry_sigma_min_m = 0.01;
  double odometry_rotation_sigma_per_m = 0.005, odometry_rotation_sigma_min = 0.002;
  double odometry_gap_inflation = 10.0;  ///< sigma factor when the odometry bridged a gap
  /// Slip gate: when an accepted scan match and the encoder odometry of the same step disagree
  /// beyond this chi-square value (6 degrees of freedom, 99.9 %: 22.46) under their combined
  /// covariance, the encoders misreported (a foot slipped) and the step's odometry factor is
  /// weakened until the disagreement is at the gate's expectation (counted: odometry_slips).
  /// Without it a 2 s slip pulls the map by centimetres against the scan matches. 0: off.
  double odometry_gate_chi2 = 22.46;
  std::size_t room_update_every_keyframes = 5;
  std::size_t full_solve_every_keyframes = 50;
  /// Where the full solve runs (docs/s-graph.md, "The full solve in the background"). 0: on the
  /// spot, on the mapper's thread; it grows with the graph (300 ms at 4,000 keyframes). N > 0:
  /// it is begun at the keyframe that calls for it and applied N keyframes later; meanwhile
  /// whoever claims it runs it (background_solve(): the node's solver thread), or the mapper
  /// does at that keyframe if nobody did. The same keyframes make the same map either way. A
  /// loop closure reaches the map N keyframes late, carried rigidly to the keyframes made
  /// meanwhile, and is refused before it is applied if that solve contradicts it. The default
  /// leaves the solve the time of 5 keyframes: a keyframe a metre or 20 degrees is about one a
  /// second walking and one every 0.35 s turning on the spot (1 rad/s), so 1.75 s at least,
  /// against 0.3 s for a full solve at 4,000 keyframes (docs/performance.md). A late one makes
  /// the mapper wait at that keyframe (counted: full_solves_waited), never a different map.
  /// Below half the graph's local window (validated): a loop waits up to twice the lag for its
  /// judgement, and its keyframes must not be sparsified meanwhile.
  std::size_t full_solve_lag_keyframes = 5;
  std::size_t max_plane_priors = 256;  ///< external wall priors held at once (SetPlanePriors)
  /// The keyframe cloud store (12 bytes a point). Full, it evicts a place's older clouds first
  /// and makes places coarser before one loses its only cloud (CloudCoverPolicy).
  std::size_t cloud_store_points = 1500000;
  std::size_t odometry_capacity = 4096;
  double odometry_max_gap_s = 0.1;
  SGraphConfig graph;
  PlaneExtractionConfig planes;
  PlaneAssociationConfig association;
  RoomMapperConfig rooms;
  FreeSpaceGridConfig grid;
  /// The free-space grid is a window that moves with the robot (FreeSpaceGrid::Follow): in a
  /// building larger than the window, rooms far from the start are still found. Off: a fixed
  /// window around the start (free space beyond is counted in grid().outside()).
  bool grid_follows_robot = true;
  LoopClosureConfig loops;
  /// Fitness leaves out points farther than 1 m from the map: a keyframe sees new space that
  /// the local map cannot contain, and that is not misalignment.
  VgicpConfig scan_matching = VgicpWithFitnessWithin(1.0);
  Status Validate() const;
  [[nodiscard]] FitnessGateConfig scan_match_fitness_gate() const;
};

/// One assembled sweep: points in the lidar frame with their time after `start_s`.
struct LidarScanView {
  std::span<const Eigen::Vector3f> points_lidar;
  std::span<const float> time_offset_s;
  double start_s = 0, end_s = 0;
};

enum class ScanOutcome : std::uint8_t { kNotKeyframe, kKeyframe, kNoOdometry };

enum class MapperStage : std::uint8_t {
  kPreprocess,
  kScanMatching,
  kPlanes,
  kFreeSpace,
  kLocalSolve,
  kLoopClosure,
  kFullSolve,
  kRooms,
  kCount
};
const char* ToString(MapperStage stage);

/// Told when each stage of a keyframe ends (core has no clock; the caller's observer has one).
class StageObserver {
 public:
  virtual ~StageObserver() = default;
  virtual void KeyframeStarted() = 0;
  virtual void StageEnded(MapperStage stage) = 0;
};

/// The newest keyframe's scan match, for evaluation against the truth (msgraphs_slam --matches).
struct ScanMatchRecord {
  bool attempted = false;       ///< false: the first keyframe, or no local map
  double from_s = 0, to_s = 0;  ///< the previous keyframe's stamp and this one's
  const char* result = "none";  ///< accepted | failed | fitness | overlap | diverged | none
  bool motion_seeded = false;   ///< accepted from the last match's pace (motion seed)
  double fitness_m2 = 0;        ///< the kept attempt's (0 where VGICP failed)
  double limit_m2 = 0;          ///< the fitness gate's limit at this keyframe
  /// Accepted: the match (previous keyframe to this one, base frames); else the odometry's step.
  Eigen::Isometry3d T_from_to = Eigen::Isometry3d::Identity();
};

struct LocalMapperStats {
  std::uint64_t scans = 0, keyframes = 0;
  std::uint64_t no_odometry = 0;  ///< scan outside the odometry buffered (skipped, counted)
  std::uint64_t odometry_gap_keyframes = 0;
  std::uint64_t odometry_slips = 0;  ///< steps whose odometry the slip gate weakened
  std::uint64_t bad_scans = 0;  ///< too few points, or mismatched spans
  /// Points of keyframe scans beyond max_scan_points, left out of the keyframe (counted).
  std::uint64_t scan_points_beyond_capacity = 0;
  std::uint64_t scan_match_accepted = 0;
  std::uint64_t scan_match_rejected_fitness = 0, scan_match_rejected_overlap = 0,
                scan_match_rejected_diverged = 0, scan_match_rejected_failed = 0;
  /// Of the accepted: taken from the last match's motion's guess (motion_seed_max_age_s), of
  /// them `preferred` where the odometry's guess was accepted too but fitted worse; the
  /// rejections above count odometry-seeded attempts that the motion's guess did not save.
  std::uint64_t scan_match_motion_seeded = 0, scan_match_motion_preferred = 0;
  /// Of the accepted: fitter than the floor allows, let through by the robot's own outlier
  /// bound (FitnessGate); and that bound at the newest keyframe.
  std::uint64_t scan_match_above_floor = 0;
  /// Sweeps registered by scan tracking, and those it could not (no local map, too few
  /// points, or the registration refused): they take the encoders' motion.
  std::uint64_t scans_tracked = 0, scans_untracked = 0;
  double scan_match_fitness_limit_m2 = 0;
  std::uint64_t loop_closures = 0, full_solves = 0;
  /// Full solves in the background (full_solve_lag_keyframes > 0): applied; and of all begun,
  /// those the mapper had to run itself or wait for at their keyframe (nobody ran them in time).
  std::uint64_t full_solves_background = 0, full_solves_waited = 0;
  /// Background full solves begun, and those whose solve failed (not applied; their loops wait
  /// for the next).
  std::uint64_t full_solves_begun = 0, full_solves_unusable = 0;
  /// Loop closures found while more than loop_checks_capacity waited for their solve: applied
  /// without the contradiction check.
  std::uint64_t loops_unchecked = 0;
  /// Keyframes the graph refused (its store full with nothing to sparsify, which a validated
  /// config rules out): the scan is skipped and the next one tries again.
  std::uint64_t keyframes_refused = 0;
  /// Odometry or scan-matching factors the graph refused (its factor store full): the keyframe
  /// then rests on whichever of the two the graph took, or on its planes alone.
  std::uint64_t chain_factors_refused = 0;
  std::size_t plane_priors = 0;            ///< external wall priors in the graph now
  std::uint64_t plane_priors_refused = 0;  ///< beyond max_plane_priors, or refused by the graph
  std::uint64_t floors_found = 0;          ///< keyframes whose floor only the floor search found
  std::size_t local_map_points_peak = 0;
};

/// Where to look for the robot after its odometry integration restarted (Relocalise): on the
/// segment between two poses of this mapper's odometry frame (where it stopped, where it would
/// be had it kept its speed), one step beyond each end, up to `lateral_m` to either side and
/// `yaw_rad` either way of the heading interpolated along it. When nothing there aligns and
/// `reach_m` > 0, anywhere within `reach_m` of where it stopped (the robot's top speed times the
/// time the node was down: it may have turned a corner, or walked back), nearest first, at
/// every heading of the search.
struct RelocaliseSearch {
  Eigen::Isometry3d T_odom_from = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d T_odom_to = Eigen::Isometry3d::Identity();
  double step_m = 0.25;  ///< seed spacing, along and across (VGICP's basin is wider)
  double lateral_m = 0.5;
  /// Every heading by default, in 10 degree steps: a legged robot turns on the spot, and in
  /// the HIL run it turned 250 degrees at a dead end while the node was down.
  double yaw_rad = 3.1416, yaw_step_rad = 0.1745;
  std::size_t max_candidates = 20000;  ///< seeds scored; the segment is cut short beyond
  /// Keyframes within this distance of the segment make the map searched, nearest first, as
  /// many as the local map holds (the robot may have walked beyond the last few keyframes).
  double map_radius_m = 10.0;
  std::size_t registrations = 6;  ///< the best-scored seeds registered (at most 8)
  double reach_m = 0;  ///< 0: the segment only
  /// Seeds scored within reach; the farthest rings are left out beyond.
  std::size_t max_reach_candidates = 400000;
  /// An aligned place is refused when more than this fraction of the scan's wall returns lie
  /// where the map saw through (LocalMapper::SeenThroughFraction). At the robot's place only
  /// what moved since (people, a door) lies there; docs/runtime.md gives the measured spread.
  double max_seen_through = 0.01;
};

struct Relocalisation {
  Eigen::Isometry3d T_odom_base = Eigen::Isometry3d::Identity();  ///< at the scan's end
  double fitness_m2 = 0;
  std::size_t candidates = 0;     ///< seeds scored
  std::size_t registrations = 0;  ///< of them registered
  bool wide = false;              ///< found by the search within reach, not on the segment
  /// Of the scan's wall returns at the answer, the fraction where the map saw through.
  double seen_through = 0;
  std::size_t contradicted = 0;  ///< places that aligned but were refused by that test
};

class LocalMapper {
 public:
  LocalMapper() = default;
  /// Waits for a background full solve a worker is running (it borrows the graph).
  ~LocalMapper();
  LocalMapper(const LocalMapper&) = delete;
  LocalMapper& operator=(const LocalMapper&) = delete;

  Status Init(const LocalMapperConfig& config);

  /// Encoder odometry (base frame in the odometry frame), in time order.
  Status AddOdometry(double stamp_s, const Eigen::Isometry3d& T_odom_base);

  /// kNoOdometry: the scan's end is not inside the buffered odometry (feed odometry first).
  Expected<ScanOutcome> AddScan(const LidarScanView& scan, StageObserver* observer = nullptr);

  /// How the newest keyframe was made, for a journal that rebuilds the mapper from its keyframe
  /// scans alone (runtime's checkpoint): its motion since the previous keyframe as tracked
  /// then, and whether a sweep registration gave it. Scan tracking makes the keyframes depend
  /// on every sweep, which the journal does not keep.
  struct KeyframeMotion {
    Eigen::Isometry3d T_last_new = Eigen::Isometry3d::Identity();
    bool tracked = false;
  };
  const KeyframeMotion& last_keyframe_motion() const { return keyframe_motion_; }

  /// Replay of a journaled keyframe: `scan` becomes a keyframe made exactly as it was live, with
  /// `motion` in place of tracking and of the spacing test. kNoOdometry as AddScan.
  Expected<ScanOutcome> ReplayKeyframe(const LidarScanView& scan, const KeyframeMotion& motion);

  /// Where `scan` was taken, in this mapper's odometry frame, when the odometry cannot say: a
  /// restarted node whose odometry integration began again at identity while the robot moved.
  /// `T_new_start`/`T_new_end` are the new odometry at the scan's start and end (only their
  /// relative motion is used, to deskew). Every seed of `search` is scored by how close a
  /// sample of the scan falls to the local map's voxels (the last keyframes); the best few are
  /// registered by VGICP, and the lowest fitness within the scan-matching thresholds (fitness,
  /// overlap) wins. Changes nothing in the map: the caller maps its new odometry frame
  /// with the answer (T_odom_base * T_new_end^-1) and goes on with AddOdometry and AddScan.
  /// The answer must also be unique: two places apart by more than two seed steps or two
  /// heading steps that both pass are an ambiguity (on the segment, the search goes on within reach).
  /// kNotFound without a keyframe; kNotConverged when no seed passes, or passes ambiguously.
  Expected<Relocalisation> Relocalise(const LidarScanView& scan,
                                      const Eigen::Isometry3d& T_new_start,
                                      const Eigen::Isometry3d& T_new_end,
                                      const RelocaliseSearch& search);

  /// A full solve now (for example at the end of a mission); a background one pending is
  /// completed and applied first.
  Status Finish();

  // ---- snapshots (local_mapper_snapshot.cpp, docs/s-graph.md "Snapshots") ----
  /// The most bytes Save can write for this mapper's config.
  std::size_t SnapshotBytes() const;
  /// Writes the mapper's state between two scans (the graph's snapshot, the odometry, the cloud
  /// store, the descriptors, the free-space grid, the plane extents, the counters). Loaded into
  /// a mapper initialised with the same config, the same scans make the same map, bit for bit.
  /// Meant for just after a keyframe (the node's snapshot writer is not built yet). The config
  /// itself is not in it: the graph's is checked, the rest (spacing, voxel sizes, thresholds)
  /// is the caller's to keep the same (the node: its config file's CRC). kWouldBlock while a
  /// background full solve is pending or any job borrows the graph, such as the distiller's
  /// marginals (save after it ended); kCapacityExceeded when `out` is too small
  /// (SnapshotBytes always suffices). `seal` kLater leaves the CRCs to SealSnapshot: the copy
  /// is then all the caller's thread pays (docs/performance.md, "Restart after a long
  /// mission"). Allocates nothing.
  Expected<std::size_t> Save(std::span<std::uint8_t> out, SnapshotSeal seal = SnapshotSeal::kNow) const;
  /// Writes the CRCs (the graph's, then the mapper's) of a snapshot Save wrote with
  /// SnapshotSeal::kLater (`snapshot`: the bytes Save returned); any thread may, the mapper is
  /// not touched. kInvalidArgument when they are not a mapper snapshot's. Allocates nothing.
  static Status SealSnapshot(std::span<std::uint8_t> snapshot);
  /// Replaces this mapper's state by a snapshot. kInvalidArgument with the mapper unchanged for
  /// bytes that are not a whole snapshot of this version (CRC-32) or whose graph has another
  /// config; one whose parts do not fit this mapper's stores or do not hold together leaves it
  /// as Init left it. Allocates (the graph's Ceres problem).
  Status Load(std::span<const std::uint8_t> in);
  /// Asks for a snapshot (Save) into `out` at the end of the next keyframe that has no full
  /// solve pending: after the solve due at that keyframe is applied and before the next one
  /// begins, so the state it holds is whole. Saving between scans instead would almost never
  /// find that moment with full_solve_lag_keyframes > 0 (a solve is pending for most
  /// keyframes). `out` must stay valid until the result is taken; SnapshotBytes() suffices. A
  /// new request replaces one not yet served; Init and Load forget it. `seal` as for Save.
  /// Allocates nothing.
  void RequestSnapshot(std::span<std::uint8_t> out, SnapshotSeal seal = SnapshotSeal::kNow);
  /// The snapshot taken for the last request (its size in `out`, or why Save refused), once;
  /// nothing while it still waits for its keyframe.
  std::optional<Expected<std::size_t>> TakeSnapshot();
  bool snapshot_requested() const { return snapshot_state_ == SnapshotState::kWanted; }

  /// The background full solve when one is begun and nobody has run it yet, for a worker
  /// thread to take (TryClaim, then Run); nullptr otherwise. The mapper must outlive the worker's
  /// use of it. See full_solve_lag_keyframes.
  SGraphSolveJob* background_solve() {
    return full_job_.pending() && !full_job_.done() ? &full_job_ : nullptr;
  }

  /// Replaces the external priors on this robot's walls (other robots' measurements of the same
  /// walls through the collaborative graph, CollabSession::PlanePriors). The next keyframe runs
  /// a full solve. Priors the graph refuses, or beyond max_plane_priors, are counted.
  Status SetPlanePriors(std::span<const PlanePrior> priors);

  const SGraph& graph() const { return graph_; }
  /// The map-from-odometry correction: T_map_base = T_map_odom * T_odom_base. At the newest
  /// keyframe, and with scan tracking at the newest tracked sweep.
  Eigen::Isometry3d T_map_odom() const { return T_map_odom_; }
  /// Encoder odometry at a keyframe (for the encoder-only baseline of the same keyframes).
  /// Identity for an id beyond the graph's store.
  Eigen::Isometry3d keyframe_odometry(std::uint32_t keyframe) const {
    return keyframe < keyframe_odometry_.size() ? keyframe_odometry_[keyframe]
                                                : Eigen::Isometry3d::Identity();
  }
  const LocalMapperStats& stats() const { return stats_; }
  const ScanMatchRecord& last_scan_match() const { return last_match_; }
  const PlaneMapper& plane_mapper() const { return planes_mapper_; }
  const RoomMapper& room_mapper() const { return rooms_; }
  const LoopCloser& loop_closer() const { return loops_; }
  const OdometryBuffer& odometry() const { return odometry_; }
  const KeyframeCloudStore& clouds() const { return clouds_; }
  /// The store's places: cell size now and how often it was doubled to make room.
  const CloudCoverPolicy& cloud_cover() const { return cover_; }
  /// A keyframe's stored cloud (base frame, store_voxel_m); empty when evicted or sparsified.
  std::span<const Eigen::Vector3f> keyframe_cloud(std::uint32_t keyframe) const {
    if (keyframe >= sequence_.size() || !graph_.keyframe_active(keyframe)) return {};
    return clouds_.Get(keyframe, sequence_[keyframe]);
  }
  const FreeSpaceGrid& grid() const { return grid_; }
  const LocalMapperConfig& config() const { return config_; }

 private:
  void Stage(StageObserver* observer, MapperStage stage) const {
    if (observer != nullptr) observer->StageEnded(stage);
  }
  /// `buffered`: deskew along this mapper's odometry buffer (AddScan); false: the caller's
  /// start and end poses only (Relocalise: a new odometry frame the buffer does not hold).
  bool Preprocess(const LidarScanView& scan,
                  const Eigen::Isometry3d& T_odom_start,
                  const Eigen::Isometry3d& T_odom_end, bool buffered);
  /// Deskewed, range-filtered, in the base frame: filtered_.
  void PrepareSweep(const LidarScanView& scan, const Eigen::Isometry3d& T_odom_start,
                    const Eigen::Isometry3d& T_odom_end, bool buffered);
  Expected<ScanOutcome> AddScanImpl(const LidarScanView& scan, StageObserver* observer,
                                    const KeyframeMotion* replay);
  /// The prior that holds what the clouds leave free: the encoders' information for `step`,
  /// never tighter than the tracking floor.
  Matrix6d HoldingPrior(const Eigen::Isometry3d& step, bool across_gap) const;
  /// Scan tracking (scan_tracking.cpp): the base at this sweep's end in the last keyframe's
  /// frame, registered when it can be, else the encoders' motion since the last sweep.
  Eigen::Isometry3d Track(const LidarScanView& scan, const Eigen::Isometry3d& T_odom_start,
                          const Eigen::Isometry3d& T_odom_end, bool across_gap);
  /// The local map for the last keyframe, built if it is not (false when it cannot be).
  bool EnsureLocalMap();
  bool BuildLocalMap(std::uint32_t last);
  bool BuildMapFrom(std::uint32_t last, std::span<const std::uint32_t> keyframes);
  bool BuildMapNear(const Eigen::Vector2d& a_map, const Eigen::Vector2d& b_map, double radius_m);
  double SeedScore(const Eigen::Isometry3d& T_last_seed) const;
  double SeenThroughFraction(const Eigen::Isometry3d& T_last_candidate) const;
  Matrix6d OdometryInformation(const Eigen::Isometry3d& delta, bool across_gap) const;
  enum class MatchOutcome : std::uint8_t { kAccepted, kFailed, kFitness, kOverlap, kDiverged };
  static const char* ToString(MatchOutcome outcome);
  /// The keyframe scan (down_) against the local map from `T_last_seed`; on acceptance the
  /// registered step and its information.
  MatchOutcome MatchFrom(const Eigen::Isometry3d& T_last_seed, Eigen::Isometry3d& T_last_new,
                         Matrix6d& information, double& fitness_m2,
                         const VgicpPrior* prior = nullptr);
  /// The step the last accepted match's motion predicts for a scan ending at end_s, with the
  /// odometry's step `delta` giving direction and rotation; false when there is none.
  bool MotionSeed(const Eigen::Isometry3d& delta, double end_s, Eigen::Isometry3d& seed) const;
  void ExtractPlanes(std::uint32_t keyframe);
  /// The full solve's schedule at a keyframe (local_mapper_full_solve.cpp): on the spot, or
  /// begun and applied full_solve_lag_keyframes later.
  void ScheduleFullSolve(bool loop);
  void ApplyBackgroundSolve();
  void BeginBackgroundSolve();
  /// The keyframe's last step: a snapshot asked for, then the background solve wanted.
  void EndKeyframe();
  template <class Archive>
  void Io(Archive& ar);  // the snapshot's own fields (local_mapper_snapshot.cpp)

  LocalMapperConfig config_;
  SGraph graph_;
  OdometryBuffer odometry_;
  KeyframeCloudStore clouds_;
  CloudCoverPolicy cover_;  ///< what a full cloud store evicts: a place's older clouds first
  PlaneMapper planes_mapper_;
  RoomMapper rooms_;
  LoopCloser loops_;
  FreeSpaceGrid grid_;
  PlaneExtractor extractor_;
  VoxelDownsampler voxel_;       ///< the local map's points (local_map_keyframes scans)
  VoxelDownsampler scan_voxel_;  ///< one scan's: a table that stays in cache, not the local map's
  KdTree tree_, local_tree_;
  GaussianVoxelMap local_map_;
  Vgicp vgicp_;
  FitnessGate fitness_gate_;
  ScanMatchRecord last_match_;
  double fitness_limit_m2_ = 0;  ///< this keyframe's, for both seeds
  BoundedVector<Eigen::Vector3f> work_, filtered_, down_, normals_, stored_, local_raw_,
      local_points_, local_normals_, world_points_;
  BoundedVector<Eigen::Matrix3f> covariances_, local_covariances_;
  BoundedVector<float> times_;
  BoundedVector<std::uint32_t> floor_members_;
  BoundedVector<ExtractedPlane> planes_;
  std::vector<std::uint64_t> sequence_;               // per keyframe slot
  std::vector<Eigen::Isometry3d> keyframe_odometry_;  // per keyframe slot
  std::vector<std::uint32_t> recent_;
  /// The sensor across a sweep, in its frame at the sweep's end: 17 instants, 6 ms apart for a
  /// 10 Hz sweep, a third of the encoders' 50 Hz period (deskew.hpp).
  std::array<Eigen::Isometry3d, 17> deskew_poses_;
  std::vector<std::pair<double, std::uint32_t>> nearby_;  // Relocalise: (distance, keyframe)
  std::vector<std::uint32_t> recent_scratch_;
  BoundedVector<std::uint32_t> prior_factors_;  // factor ids of the current plane priors
  // Scan tracking: the base at the last tracked sweep in the last keyframe's frame, and the
  // encoders there; the local map's keyframe (kNoKeyframe: none or overwritten).
  static constexpr std::uint32_t kNoKeyframe = 0xFFFFFFFFu;
  bool have_track_ = false;
  Eigen::Isometry3d track_T_last_base_ = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d track_T_odom_ = Eigen::Isometry3d::Identity();
  std::uint32_t local_map_keyframe_ = kNoKeyframe;
  std::uint32_t local_map_failed_ = kNoKeyframe;  ///< a build failed for it: not retried per sweep
  bool prepared_ = false;  ///< filtered_ holds this scan's sweep (tracking prepared it)
  std::uint32_t untracked_sweeps_ = 0;  ///< since the last tracked sweep or keyframe
  KeyframeMotion keyframe_motion_;
  BoundedVector<Eigen::Vector3f> track_down_, track_normals_;
  BoundedVector<Eigen::Matrix3f> track_covariances_;
  KdTree track_tree_;
  std::uint64_t next_sequence_ = 1;
  bool have_keyframe_ = false;
  std::uint32_t last_keyframe_ = 0;
  Eigen::Isometry3d last_odometry_ = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d T_map_odom_ = Eigen::Isometry3d::Identity();
  double path_m_ = 0;
  // The last accepted scan match: metres it moved, over seconds (0: none yet), ending at
  // motion_end_s_.
  double motion_m_ = 0, motion_s_ = 0, motion_end_s_ = 0;
  std::size_t keyframes_since_rooms_ = 0, keyframes_since_full_ = 0;
  // The background full solve: the job, the keyframe count at which it is applied, whether
  // another is wanted, and the loop closures waiting for a solve to judge them (pending: since
  // the job began; job_loops_: in it).
  static constexpr std::size_t kLoopChecks = 16;
  SGraphSolveJob full_job_;
  std::uint64_t keyframe_count_ = 0, full_apply_at_ = 0;
  bool full_wanted_ = false;
  BoundedVector<std::uint32_t> pending_loops_, job_loops_;
  // The snapshot asked for (RequestSnapshot): its buffer and, once taken, its result.
  enum class SnapshotState : std::uint8_t { kNone, kWanted, kTaken };
  SnapshotState snapshot_state_ = SnapshotState::kNone;
  std::span<std::uint8_t> snapshot_out_;
  SnapshotSeal snapshot_seal_ = SnapshotSeal::kNow;
  Expected<std::size_t> snapshot_result_ = std::size_t{0};
  LocalMapperStats stats_;
};

}  // namespace msgraphs::core
