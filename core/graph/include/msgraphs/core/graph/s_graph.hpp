// SPDX-License-Identifier: MIT
// The local S-Graph of one robot: an incremental four-layer factor graph on Ceres (private).
//
// Layers and their nodes (docs/s-graph.md):
// - keyframes: SE(3) poses T_map_keyframe (quaternion + translation on Ceres' quaternion
//   manifold). Keyframe 0 is the origin and fixes the gauge: it is held constant, always.
// - walls (and the floor/ceiling planes): planes n.p + d = 0 in the map frame with a minimal
//   parameterisation: the unit normal on Ceres' SphereManifold<3> (2 dof) and d (1 dof).
// - rooms: a 2-D centre; four-wall rooms and two-wall corridors.
// - floors: a 2-D centre tied weakly to each room.
//
// Factors: relative poses between keyframes (encoder odometry, scan matching, loop closures,
// the composed factors that sparsification leaves), keyframe-to-plane, room-to-walls,
// corridor-to-walls, wall-to-wall (a wall found twice) and floor-to-room. Every factor has a
// Huber kernel whose threshold is in standard deviations of its whitened residual.
//
// Bounded: keyframes, planes, rooms and factors have capacities from the config. When the
// keyframe store is full, a keyframe is sparsified: removed and its neighbours joined by the
// composition of its two relative-pose hops; its loop closures are carried to a neighbour
// through the composed hop (docs/s-graph.md says which one and why). There is always one to
// remove, so the store never overflows: AddKeyframe would refuse (counted) rather than write
// past it.
//
// Bad input never enters: non-finite or non-rigid poses, stamps that go backwards or repeat,
// indefinite information, a plane seen from behind, factors between missing nodes; each is
// refused with a status and counted. A solve that leaves anything non-finite is undone.
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <span>

#include "msgraphs/base/expected.hpp"
#include "msgraphs/base/snapshot_header.hpp"

namespace msgraphs::core {

using Matrix6d = Eigen::Matrix<double, 6, 6>;

struct SGraphConfig {
  std::size_t max_keyframes = 4096;  ///< active keyframes; beyond, sparsification
  std::size_t max_planes = 2048;
  std::size_t max_rooms = 256;
  /// Factor records (every kind). Enough for ~12 per keyframe by default; a full store refuses
  /// new factors with kCapacityExceeded (counted).
  std::size_t max_factors = 65536;
  /// Huber thresholds, in standard deviations of the whitened residual.
  double huber_relative_pose = 3.0;
  double huber_loop_closure = 1.0;
  double huber_plane = 2.0;
  double huber_room = 2.0;
  double room_sigma_m = 0.05;       ///< room centre against its walls' midlines
  double wall_wall_sigma = 0.02;    ///< a wall found twice: normals (rad) and offsets (m)
  double floor_room_sigma_m = 1.0;  ///< weak on purpose: rooms hold the floor, not the reverse
  /// Local solve: the newest `local_window_keyframes` keyframes and what they observe move;
  /// everything older is held. Bounded iterations and solver time.
  std::size_t local_window_keyframes = 20;
  int local_max_iterations = 10;
  double local_max_seconds = 0.05;
  /// A free plane's observations by held keyframes reach the local solve as one sum
  /// (docs/s-graph.md, "Solves"). true: the sum is kept between solves and only what left the
  /// window since is added, so a wall seen from a thousand keyframes (the floor: every one)
  /// costs what the newest keyframes add; it is taken afresh after anything that moves a held
  /// keyframe (a full solve, sparsification). false: summed afresh at every local solve, at a
  /// cost that grows with the mission (the reference the incremental sum is tested against).
  bool incremental_held_sums = true;
  /// Sparsification carries a removed keyframe's plane observations to a neighbour through a
  /// hop (docs/s-graph.md, "Sparsification"). A hop that several carried factors rest on enters
  /// each inflated (covariance intersection); this is the share of the hop that the carried
  /// plane observations get together, the rest going to the joined chain and the carried loops.
  /// 0: plane observations are dropped, not carried. Below 1: the chain always keeps a share.
  /// Any value in (0, 1) is consistent; 0.8 mapped best of 0.2 / 0.5 / 0.8 / 0.95 on a 1-hour
  /// office recording and two generated buildings (docs/performance.md, "plane observations
  /// carried"): a wall seen from a removed keyframe has no other route into the graph, the
  /// neighbours are tied by scan matching and loops besides the chain.
  double sparsify_plane_share = 0.8;
  /// Full solve (after a loop closure and every so often): everything but the origin moves.
  int full_max_iterations = 100;
  double full_max_seconds = 2.0;
  Status Validate() const;
};

enum class RelativePoseKind : std::uint8_t { kOdometry, kScanMatch, kLoopClosure, kSparsified };
enum class PlaneClass : std::uint8_t { kWall, kFloor, kCeiling };
enum class SolveKind : std::uint8_t { kLocal, kFull };
class SGraphSolveJob;

/// A plane measured in a keyframe's frame (n towards the sensor) with the covariance of the
/// minimal perturbation (alpha, beta, delta_d) along basis_u and basis_v, as PlaneExtractor
/// reports it.
struct PlaneMeasurement {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitX();
  double d = 0;
  Eigen::Vector3d basis_u = Eigen::Vector3d::UnitY();
  Eigen::Vector3d basis_v = Eigen::Vector3d::UnitZ();
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();
};

/// What of a graph's evidence a marginals job keeps (SGraph::BeginPlaneMarginals).
enum class PlaneEvidence : std::uint8_t {
  kAll,  ///< the graph's problem as it is
  kOwn,  ///< without the plane priors: the evidence of this graph's own observations only
};

/// An external measurement of a map plane: normal and offset in this map frame, covariance over
/// (alpha, beta, delta_d) along WallBasis(normal) (distilled_graph.hpp).
struct PlanePrior {
  std::uint32_t plane = 0;
  Eigen::Vector3d normal = Eigen::Vector3d::UnitX();
  double d = 0;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();
};

struct MapPlane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitX();  ///< unit; the side it was seen from
  double d = 0;
  /// The plane's information from its observations, conditional on the keyframe estimates at
  /// the time, over the minimal perturbation (alpha, beta, delta_d) along basis_u / basis_v (the
  /// extractor's convention, in the map frame). Zero before the first observation.
  Eigen::Matrix3d information = Eigen::Matrix3d::Zero();
  Eigen::Vector3d basis_u = Eigen::Vector3d::UnitY();
  Eigen::Vector3d basis_v = Eigen::Vector3d::UnitZ();
  PlaneClass plane_class = PlaneClass::kWall;
  std::uint32_t observations = 0;  ///< observations ever added (how established it is)
  /// Observations in the graph now: sparsification and RemoveKeyframe carry a removed
  /// keyframe's to a neighbour (fused with the neighbour's own where it has one), or drop them
  /// with SGraphConfig::sparsify_plane_share = 0 or a carry that fails (sparsify_planes_dropped).
  /// Zero means nothing measures the plane any more (its estimate stays, its marginal is
  /// undefined: PlaneMarginals refuses it).
  std::uint32_t live_observations = 0;
  /// Stamp of the newest keyframe that observed it (a stamp, not a slot: slots are reused).
  double last_observed_s = -std::numeric_limits<double>::infinity();
  bool active = false;
};

enum class RoomShape : std::uint8_t { kFourWall, kCorridor };

struct MapRoom {
  RoomShape shape = RoomShape::kFourWall;
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  /// Walls: low x, high x, low y, high y of the room frame (a corridor: the first pair only;
  /// -1 where absent). Every pair faces into the room.
  std::array<std::int32_t, 4> walls{-1, -1, -1, -1};
  Eigen::Vector2d corridor_anchor = Eigen::Vector2d::Zero();  ///< where along a corridor it is
  bool active = false;
};

struct SGraphSolveReport {
  SolveKind kind = SolveKind::kLocal;
  bool usable = false;     ///< the solver finished with a finite state (else it was undone)
  bool converged = false;  ///< met its tolerances (not just the iteration or time limit)
  int iterations = 0;
  double initial_cost = 0, final_cost = 0;
  double seconds = 0;  ///< as Ceres measured it
  std::size_t free_keyframes = 0;
};

struct SGraphStats {
  std::size_t keyframes = 0, keyframes_peak = 0, sparsified = 0;
  // Keyframes removed (sparsified, or on request: RemoveKeyframe) that carried a loop closure
  // (sparsification takes one only when no keyframe without one was left), relative factors
  // carried from a removed keyframe to a neighbour through the composed hop, of them fused into
  // a parallel factor already there, and constraints that could not be carried over (a hop
  // without a measurement, a composition that is not positive definite, a full factor store):
  // counted, and lost (sparsification at a full store only; docs/s-graph.md).
  std::size_t sparsified_with_loops = 0, sparsify_carried = 0, sparsify_merged = 0,
              sparsify_dropped = 0;
  /// Plane observations of removed keyframes carried to a neighbour, of them fused into the
  /// neighbour's own observation of the same plane, and those not carried (no hop with a
  /// measurement, a covariance that is not positive definite, sparsify_plane_share 0).
  std::size_t sparsify_planes_carried = 0, sparsify_planes_fused = 0,
              sparsify_planes_dropped = 0;
  /// Keyframes refused because the store was full and nothing could be sparsified, and
  /// sparsifications that found nothing to remove. Both stay 0 under a validated config (a
  /// keyframe always lies between the origin and the local window); never a write past the store.
  std::uint64_t rejected_keyframes = 0, sparsify_failed = 0;
  /// Keyframes removed on request (RemoveKeyframe), not counted in `sparsified`.
  std::uint64_t removed_keyframes = 0;
  /// Planes whose last live observation went: with its keyframe, by sparsification at a full
  /// store with carrying off (which then takes a plane's last observer only when every
  /// candidate of the same loop tier is one; a removal on request never does) or a carry that
  /// failed, or by RemoveFactor. Such a plane keeps its
  /// estimate; PlaneMarginals refuses it (MapPlane::live_observations).
  std::uint64_t planes_unobserved = 0;
  std::size_t planes = 0, rooms = 0, floors = 0;
  std::size_t factors = 0, factors_peak = 0;
  std::array<std::size_t, 4> relative_factors{};  ///< by RelativePoseKind
  std::size_t plane_factors = 0, room_factors = 0, wall_wall_factors = 0, floor_factors = 0,
              plane_prior_factors = 0;
  // Refused input, by reason.
  std::uint64_t rejected_pose = 0;          ///< non-finite or non-rigid pose or measurement
  std::uint64_t rejected_stamp = 0;         ///< keyframe stamp not after the previous one
  std::uint64_t rejected_information = 0;   ///< information not symmetric positive definite
  std::uint64_t rejected_behind = 0;        ///< plane seen from its back side
  std::uint64_t rejected_missing_node = 0;  ///< factor to a node that does not exist (any more)
  std::uint64_t rejected_capacity = 0;
  std::uint64_t solves = 0, solves_not_converged = 0, solves_undone = 0;
  /// The most residual blocks a local solve's window problem held (its cost follows this, not
  /// the graph's size).
  std::size_t window_residuals_peak = 0;
  /// Free planes whose held observations a local solve summed afresh (a full solve or
  /// sparsification moved held keyframes since, or the plane was out of the window longer than
  /// a window), and held observations added to a kept sum as their keyframes left the window.
  std::uint64_t held_sums_rebuilt = 0, held_observations_added = 0;
  /// Full solves run in the background (SGraphSolveJob): applied, and refused as unusable.
  std::uint64_t background_applied = 0, background_unusable = 0;
  /// Removed cost functions kept because a job begun before their removal may still evaluate
  /// them (freed once every such job has ended borrowing).
  std::size_t retired_costs = 0;
  /// Goes up at every call that may change the graph (its structure or its estimates): equal
  /// revisions, the same graph (the distiller skips its work on it).
  std::uint64_t revision = 0;
  /// Bytes of our own stores (fixed at Init). Ceres' problem grows with the graph, and the
  /// graph is bounded, so its size is bounded too; tools report the process peak.
  std::size_t store_bytes = 0;
};

class SGraph {
 public:
  SGraph();
  ~SGraph();
  SGraph(const SGraph&) = delete;
  SGraph& operator=(const SGraph&) = delete;

  /// kWouldBlock while a background solve job borrows from this graph (apply or drop it first).
  Status Init(const SGraphConfig& config);

  /// A new keyframe with its initial estimate. The first one becomes the origin (held fixed).
  /// kOutOfOrder when `stamp_s` is not after the last keyframe's; kInvalidArgument for a
  /// non-rigid or non-finite pose. When the store is full, one keyframe is sparsified after the
  /// new one is in (the local window includes it); kCapacityExceeded (rejected_keyframes) only
  /// if nothing could be, which a validated config rules out.
  Expected<std::uint32_t> AddKeyframe(double stamp_s, const Eigen::Isometry3d& T_map_keyframe);

  /// Relative pose measurement T_from_to with its information over [t; rotation vector].
  /// Returns the factor's id (for FactorChi2 / RemoveFactor).
  Expected<std::uint32_t> AddRelativePose(std::uint32_t from,
                                          std::uint32_t to,
                                          const Eigen::Isometry3d& T_from_to,
                                          const Matrix6d& information,
                                          RelativePoseKind kind);

  /// The squared whitened residual of a factor at the current estimate, without its robust
  /// kernel: how far the optimised graph disagrees with it, in units of its own variance.
  Expected<double> FactorChi2(std::uint32_t factor) const;
  /// Removes a factor (a loop closure the rest of the graph contradicts).
  Status RemoveFactor(std::uint32_t factor);

  /// Removes a keyframe as sparsification does (docs/s-graph.md): its loop closures carried to
  /// a neighbour through the hop that leads there, its neighbours joined by the composition of
  /// its two hops, its plane observations carried to a neighbour (dropped with
  /// sparsify_plane_share = 0), its slot freed for a later keyframe. For a
  /// caller that knows the keyframe is redundant (a revisit of a place another keyframe keeps).
  /// A carried loop is another factor (it may take another id, or be fused into a parallel
  /// one), so a caller that holds loop factor ids (loops still to be judged) passes them as
  /// `keep_factors`: a keyframe one of them ends at is kept, and no loop is fused into one.
  /// kNotFound for an inactive id; kInvalidArgument for the origin, a keyframe in the local
  /// window, one a kept factor ends at, or one whose removal would lose a constraint (a loop
  /// with no hop to carry it, a hop without a measurement, with carrying off a plane's last
  /// live observation): unlike sparsification at a full store, a removal on request drops
  /// nothing a validated hop can carry (a carry whose covariance is numerically singular is
  /// still dropped and counted: sparsify_planes_dropped). A
  /// background job begun before keeps what it borrowed (ApplyFullSolve skips the keyframe).
  Status RemoveKeyframe(std::uint32_t id, std::span<const std::uint32_t> keep_factors = {});

  /// A new plane landmark in the map frame (normal normalised here).
  Expected<std::uint32_t> AddPlane(const Eigen::Vector3d& normal_map,
                                   double d_map,
                                   PlaneClass plane_class);

  /// Keyframe-to-plane factor. kInvalidArgument (counted as "behind") when the keyframe's
  /// current estimate lies behind the plane by more than `behind_margin_m` or the measured
  /// normal disagrees with the predicted one by more than 60 degrees: a wall seen from behind is
  /// the other face of the wall, never this landmark.
  Status AddPlaneObservation(std::uint32_t keyframe,
                             std::uint32_t plane,
                             const PlaneMeasurement& measurement,
                             double behind_margin_m = 0.1);

  /// A room (or corridor) node and its wall factor. For a corridor only walls[0..1] are used and
  /// `corridor_anchor` fixes the position along it.
  Expected<std::uint32_t> AddRoom(const MapRoom& room);
  /// Replaces the room's walls (a better wall pair found, a corridor completed to a room).
  Status UpdateRoom(std::uint32_t room, const MapRoom& updated);
  Status RemoveRoom(std::uint32_t room);

  /// Two landmarks found to be the same wall: ties them together.
  Status AddWallWall(std::uint32_t plane_a, std::uint32_t plane_b);
  /// A prior on a plane from outside this graph (another robot's measurement of the same wall,
  /// through the collaborative graph). Returns the factor's id (RemoveFactor replaces it).
  Expected<std::uint32_t> AddPlanePrior(const PlanePrior& prior);

  /// Creates the floor node (once) at `centre`, or moves its estimate. Each room joins it with
  /// a weak factor through AddFloorRoom.
  Status SetFloor(const Eigen::Vector2d& centre);
  Status AddFloorRoom(std::uint32_t room);

  /// Solves the local window (the newest keyframes and what they see; allocates its window
  /// problem) or the whole graph. Whatever order Ceres holds the graph's blocks in, every
  /// problem handed to it lists nodes and factors by their slots (RebuildProblem).
  Expected<SGraphSolveReport> Solve(SolveKind kind);

  /// Rebuilds the graph's Ceres problem from its own records, nodes and factors added newest
  /// slot first, so that Ceres holds them in another order at other addresses. Nothing the
  /// graph computes depends on that order, so it solves as before, bit for bit (tested); a
  /// snapshot's load builds the problem afresh from the records too (in slot order).
  /// kWouldBlock while a job borrows from the graph. Allocates.
  Status RebuildProblem();

  // ---- snapshots (s_graph_snapshot.cpp, docs/s-graph.md "Snapshots") ----
  /// The most bytes Save can write for this graph's config.
  std::size_t SnapshotBytes() const;
  /// Writes the whole graph (every record in its slot, the free lists in their order, the held
  /// sums, the counters, each factor's measurement) into `out`; returns the bytes written.
  /// Loaded into a graph initialised with the same config, it goes on bit for bit as this one
  /// would. kWouldBlock while a full solve is pending (a job that only borrows the costs, such
  /// as the marginals, does not stop it: both only read); kCapacityExceeded when `out` is too
  /// small (SnapshotBytes always suffices). `seal` kLater leaves the CRC to SealSnapshot (on
  /// another thread, say). Allocates nothing.
  Expected<std::size_t> Save(std::span<std::uint8_t> out, SnapshotSeal seal = SnapshotSeal::kNow) const;
  /// Writes the CRC of a snapshot Save wrote with SnapshotSeal::kLater (`snapshot`: the bytes
  /// Save returned). kInvalidArgument when they are not a graph snapshot's.
  static Status SealSnapshot(std::span<std::uint8_t> snapshot);
  /// Replaces this graph by a snapshot. kInvalidArgument, with the graph unchanged, for bytes
  /// that are not a whole snapshot of this version (CRC-32 checked) or that were made with
  /// another config; a snapshot whose records do not hold together (links, free lists, counts,
  /// each factor's kind, loss and nodes against its record) leaves the graph empty (as Init left
  /// it). A load that replaced the graph (loaded, or left it empty) moves its revision past the
  /// one before; a refusal that left it unchanged does not. kWouldBlock while a job borrows from
  /// the graph. Allocates (Ceres' problem).
  Status Load(std::span<const std::uint8_t> in);

  // ---- the full solve in the background (s_graph_solve_job.hpp) ----
  /// Copies the graph as it is now into `job` (sized by its Init with this graph's config) for a
  /// full solve elsewhere. kWouldBlock while another job is pending on this graph;
  /// kInvalidArgument when the job was sized for a smaller graph. No allocation.
  Status BeginFullSolve(SGraphSolveJob& job);
  /// After job.Complete(): puts the solution back. Keyframes and planes the job held take the
  /// solution; rooms and the floor the solution plus what the graph did to them since the copy
  /// (re-centred); keyframes, planes, rooms added since move rigidly with the newest keyframe
  /// the job held that is still in the graph, from where it is now to its solution. An
  /// unusable solve (non-finite, failed) is not applied: the report says so and the graph is as
  /// it was. Either way the job is finished.
  Expected<SGraphSolveReport> ApplyFullSolve(SGraphSolveJob& job);
  /// Finishes a job without applying it (after Complete, or before anybody claimed it).
  void DropFullSolve(SGraphSolveJob& job);
  /// Copies the graph as it is now into `job` for the marginal covariances of planes `ids`
  /// (what PlaneMarginals would give now), computed by the job's Run at the copied estimates
  /// without solving: the distiller's marginals off the graph's thread. The graph lends its
  /// costs until Run returns; read the job after Complete, then Release it. kWouldBlock when the
  /// job is pending; kNotFound for a plane not in the optimisation; kInvalidArgument for one with
  /// no live observation (as PlaneMarginals); kCapacityExceeded beyond the
  /// job's plane capacity. No allocation.
  ///
  /// PlaneEvidence::kOwn leaves the plane priors (AddPlanePrior: what other robots said) out of
  /// the copy; when there were any, Run first solves the copy without them, so the job's
  /// covariances and estimates (SGraphSolveJob::PlaneEstimate, RoomCentre, FloorCentre) hold
  /// this graph's own evidence only: what a robot may tell others without telling them back
  /// what they told it (rumour-free distillation, docs/multi-robot.md).
  Status BeginPlaneMarginals(SGraphSolveJob& job,
                             std::span<const std::uint32_t> ids,
                             PlaneEvidence evidence = PlaneEvidence::kAll) const;
  /// FactorChi2 at the job's solution (done jobs only): how the solve that included the factor
  /// judges it, before applying. kNotFound when the factor was not in the job or was removed;
  /// kNotConverged when the job's solution is not usable (it judges nothing).
  Expected<double> FactorChi2(const SGraphSolveJob& job, std::uint32_t factor) const;
  /// Whether `factor` is an active loop-closure factor (a factor id kept across keyframes may
  /// have been freed by sparsification and reused by another factor).
  bool IsLoopFactor(std::uint32_t factor) const;
  /// Whether `factor` is an active plane prior (AddPlanePrior).
  bool IsPlanePriorFactor(std::uint32_t factor) const;

  // ---- state ----
  std::size_t keyframe_slots() const;  ///< ids handed out so far (active or sparsified)
  /// The active keyframes in time order: FirstKeyframe() is the origin, NextKeyframe(k) the
  /// active keyframe after k; kNoKeyframe when there is none (an empty graph, after the newest,
  /// or k not active). Slot order is not time order: sparsification frees slots and the next
  /// keyframes take them, so whatever needs time order (a trajectory file, a chain of edges,
  /// "the keyframes since") walks this way.
  static constexpr std::uint32_t kNoKeyframe = 0xFFFFFFFFu;
  std::uint32_t FirstKeyframe() const;
  std::uint32_t NextKeyframe(std::uint32_t id) const;
  bool keyframe_active(std::uint32_t id) const;
  Eigen::Isometry3d keyframe_pose(std::uint32_t id) const;
  double keyframe_stamp(std::uint32_t id) const;
  std::size_t plane_slots() const;
  MapPlane plane(std::uint32_t id) const;
  /// Marginal covariances of planes `ids` from the whole optimisation (the uncertainty of the
  /// keyframes that saw them included), over (alpha, beta, delta_d) along each plane's basis_u /
  /// basis_v. kDegenerate when the problem is rank deficient; kInvalidArgument for a plane with
  /// no live observation (its marginal is undefined); kCapacityExceeded for more planes than
  /// max_planes; kWouldBlock when every job slot borrows the graph already. It runs a marginals
  /// job (BeginPlaneMarginals, kAll) at once, made at its first call after Init (about 5 MB at
  /// the default config, outside store_bytes), so its result never depends on where the heap
  /// put the graph's stores. The graph's thread only. Allocates (Ceres): call it at the
  /// distillation cadence, not on the per-keyframe path.
  Status PlaneMarginals(std::span<const std::uint32_t> ids,
                        std::span<Eigen::Matrix3d> covariances) const;
  std::size_t room_slots() const;
  MapRoom room(std::uint32_t id) const;
  bool has_floor() const;
  /// Plane priors were added since the last converged full solve without any (on the spot or
  /// applied from the background): the estimates may hold what they said, even once they are
  /// removed. A kOwn marginals job then solves its copy (BeginPlaneMarginals).
  bool estimates_hold_priors() const;
  Eigen::Vector2d floor_centre() const;
  /// The newest keyframes (oldest first, up to out.size()) that are active.
  std::size_t RecentKeyframes(std::span<std::uint32_t> out) const;
  SGraphStats stats() const;
  const SGraphConfig& config() const;

 private:
  struct Impl;
  struct SnapshotAccess;  // s_graph_snapshot.cpp
  // Copies every estimate and the residual blocks into a job (BeginFullSolve,
  // BeginPlaneMarginals), the plane priors' blocks left out with kOwn; the job then borrows the
  // graph's costs.
  Status CopyIntoJob(SGraphSolveJob& job, PlaneEvidence evidence) const;
  std::unique_ptr<Impl> impl_;
};

}  // namespace msgraphs::core
