// SPDX-License-Identifier: MIT
// Distillation (paper section V): the local S-Graph reduced to what other robots need: the
// origin (this robot's map frame, implicit), walls with their covariances, rooms with their
// walls, and the floor. Keyframes stay home.
//
// Versioned and incremental: each wall and room carries the graph version in which it last
// changed by more than the resend thresholds, so the codec can send only what changed since
// what a peer acknowledged. An Update that finds the S-Graph at the revision of the last one
// (SGraphStats::revision) and nothing new to use computes nothing.
//
// The walls' marginal covariances (`marginal_covariances`, the default) come from one
// factorisation of the whole S-Graph: 0.045 s at 300 keyframes, 1.04 s at 4,000 (p50), too long for the
// SLAM thread at every exchange (issue 19). In the background they take two steps: at the
// exchange, BeginMarginals copies the graph into a marginals job (SGraph::BeginPlaneMarginals:
// a memory copy) that whoever claims it runs (marginals_job(): the node's marginals thread);
// once marginals_ready(), Update(..., kBackground) distils with them: covariances of the graph
// as it was at BeginMarginals, estimates as they are at the Update (a few scans later). A wall
// that became shareable in between waits for the next exchange
// (stats().walls_awaiting_marginals) rather than go out with its conditional covariance,
// 1-30x smaller. An Update whose job nobody claimed runs it itself (the same result on any
// thread); one whose job a runner has not finished never waits: it keeps the marginals it has.
// kNow computes them in the Update for the graph as it is (the evaluation's lock-step
// missions, a node whose inputs ended, the tests). When a computation fails (a rank-deficient
// problem) the conditional covariances stand in for walls without a marginal.
//
// Rumour-free (issue 19): a robot's local S-Graph may hold plane priors, what its peers said
// about its walls (CollabSession::PlanePriors). What it distils must not hold them, or a peer
// would get its own information back as if it were new, and both would grow more certain with
// every exchange (double counting). So the marginals job leaves the priors out
// (PlaneEvidence::kOwn) and solves the copy without them; while the graph's estimates may hold
// the priors' pull (SGraph::estimates_hold_priors: priors added since the last converged full
// solve without any), every distilled estimate (walls, room centres and sizes, the floor) and
// covariance comes from that job: this robot's own evidence, as of the job's copy. An element
// the job did not hold (new since) waits for the next job. A graph never pulled is distilled
// as before (estimates as they are at the Update; kNow bit for bit). Without
// marginal_covariances there is no job: the conditional covariances hold no prior, but the
// estimates then carry the priors' pull (not rumour-free: for tests and the allocation-free
// path, not for a fleet that feeds back). Limits: a room's shape and walls are the graph's at
// the Update, its centre the job's; data association and wall extents ran on the pulled map.
//
// Memory: stores and the marginals job are sized at Init. Update allocates nothing when the
// marginals job was run elsewhere (kBackground) or without marginals; it allocates through Ceres
// when it computes them itself. The graph must outlive a distiller whose job is pending (the job
// borrows its costs); a thread running the job must be done before the distiller goes.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "msgraphs/base/expected.hpp"
#include "msgraphs/core/graph/distilled_graph.hpp"
#include "msgraphs/core/graph/s_graph.hpp"
#include "msgraphs/core/graph/s_graph_solve_job.hpp"
#include "msgraphs/core/slam/plane_mapper.hpp"

namespace msgraphs::core {

/// When Update computes the walls' marginal covariances (see above).
enum class MarginalsTiming { kNow, kBackground };

struct DistillerConfig {
  std::uint32_t min_wall_observations = 3;  ///< walls of a room are always included
  double resend_distance_m = 0.01;          ///< a wall's offset or a room's centre moved this much
  double resend_angle_rad = 0.0017;         ///< or a normal turned this much (0.1 degree)
  double resend_covariance_ratio = 0.5;     ///< or a wall's uncertainty changed by this factor
  /// The floor's height in the map frame: the map frame is the first base pose, so minus the
  /// base's height above the floor (LocalMapperConfig::base_height_m).
  double floor_z_m = 0;
  /// Wall covariances as marginals of the whole local optimisation (keyframe uncertainty
  /// included); otherwise, or when the problem is rank deficient, the plane's own information
  /// (conditional on the keyframes).
  bool marginal_covariances = true;
  std::size_t max_walls = 1024;
  std::size_t max_rooms = 256;
  Status Validate() const;
};

class Distiller {
 public:
  Distiller() = default;
  ~Distiller();  ///< releases a pending marginals job (its graph must still be there)
  Distiller(const Distiller&) = delete;
  Distiller& operator=(const Distiller&) = delete;

  /// `graph` gives the capacities of the S-Graph it will distil (its plane and room ids).
  Status Init(std::uint16_t robot, const SGraphConfig& graph, const DistillerConfig& config);

  /// Refreshes the distilled graph from the local one; true when something changed (the graph's
  /// version then went up and the changed elements carry it). Always the same graph.
  bool Update(const SGraph& graph,
              const PlaneMapper& planes,
              MarginalsTiming marginals = MarginalsTiming::kNow);

  /// The first step of a kBackground Update: begins the marginals job for the walls shareable
  /// now, unless one is pending or the graph is at the revision of the last one. True when a
  /// job was begun.
  bool BeginMarginals(const SGraph& graph);
  /// Nothing is computing: the next kBackground Update has the newest marginals.
  bool marginals_ready() const { return !job_.pending() || job_.done(); }
  /// The marginals job BeginMarginals began, until it is done: for another thread to take
  /// (TryClaim, then Run; a claim fails once somebody has it); nullptr otherwise.
  SGraphSolveJob* marginals_job() { return job_.pending() && !job_.done() ? &job_ : nullptr; }

  const DistilledGraph& graph() const { return out_; }
  struct Stats {
    std::uint64_t marginal_updates = 0, marginal_failures = 0;
    std::uint64_t unchanged = 0;  ///< Updates that found the S-Graph as it was (nothing computed)
    /// kBackground: marginals jobs begun; those an Update ran itself (nobody had claimed them);
    /// Updates that found the job still running (never waited for: taken by a later Update);
    /// walls held back, summed over Updates, because they had no marginal yet.
    std::uint64_t marginals_begun = 0, marginals_run_at_update = 0, marginals_not_ready = 0;
    std::uint64_t walls_awaiting_marginals = 0;
    /// Rumour-free: jobs solved without the plane priors (own evidence), those of them that did
    /// not converge within the iteration cap (their result is used), that failed (not used: the
    /// distilled graph keeps what it had); walls and rooms held back, summed over Updates,
    /// because the job that gives the own estimates did not hold them.
    std::uint64_t own_evidence_jobs = 0, own_solve_unconverged = 0, own_solve_failures = 0;
    std::uint64_t walls_awaiting_estimates = 0, rooms_awaiting_estimates = 0;
    /// Walls not shared, summed over Updates, because nothing measures them any more (their
    /// observers were sparsified away: MapPlane::live_observations). Their marginal is
    /// undefined; one shared before keeps what it was sent with.
    std::uint64_t walls_unobserved = 0;
  };
  const Stats& stats() const { return stats_; }

 private:
  DistillerConfig config_;
  DistilledGraph out_;
  std::vector<std::int32_t> wall_slot_;  // local plane id -> index in out_.walls, -1 if absent
  std::vector<std::int32_t> room_slot_;  // local room id -> index in out_.rooms, -1 if absent
  std::vector<std::uint8_t> needed_;     // per local plane: a room uses it
  BoundedVector<std::uint32_t> eligible_;
  // Takes the result of the pending marginals job into marginal_ (true when it brought one).
  bool CollectMarginals();
  // The walls to share now, into eligible_ (and needed_).
  void FindEligible(const SGraph& graph);
  std::uint64_t unobserved_ = 0;  ///< walls FindEligible left out: nothing measures them
  // Computes the marginals of eligible_ now, into marginal_.
  void MarginalsNow(const SGraph& graph);
  // Takes computed covariances (one per id) into marginal_; a size mismatch is a failure.
  void StoreMarginals(std::span<const std::uint32_t> ids, std::span<const Eigen::Matrix3d> covariances);
  // Takes a done job's covariances and estimates (the own evidence's), then releases it.
  void TakeJob();
  // kNow with the own evidence: the job run here, on this thread.
  void OwnMarginalsNow(const SGraph& graph);
  // No own estimate is known any more (until the next job succeeds).
  void ForgetOwnEstimates();
  // Where an element's estimate comes from: the graph now, or the newest job (own evidence).
  bool WallEstimate(const SGraph& graph, std::uint32_t id, bool own, Eigen::Vector3d& n, double& d) const;

  std::vector<Eigen::Matrix3d> marginal_;     // per local plane id: its newest marginal
  std::vector<Eigen::Matrix3d> now_;          // kNow's, by position in eligible_
  std::vector<std::uint8_t> marginal_known_;  // per local plane id
  // The newest job's estimates (own evidence), per local plane / room id, and the floor's.
  std::vector<Eigen::Vector4d> own_plane_;
  std::vector<Eigen::Vector2d> own_room_;
  std::vector<std::uint8_t> own_plane_known_, own_room_known_;
  Eigen::Vector2d own_floor_ = Eigen::Vector2d::Zero();
  bool own_floor_known_ = false;
  bool marginals_failed_ = false;             // the newest computation failed
  SGraphSolveJob job_;
  std::optional<std::uint64_t> job_revision_;  // the S-Graph's when the last job was begun
  Stats stats_;
  bool updated_once_ = false;
  std::uint64_t revision_ = 0;  // the S-Graph's at the last Update
};

}  // namespace msgraphs::core
