// SPDX-License-Identifier: MIT
// One robot's side of Multi S-Graphs, transport-agnostic: what the onboard node runs between
// its local S-Graph and the radio link, and what msgraphs_collab runs between in-process robots.
//
// - Ingest(exchange): takes what the publisher (collab_publisher.hpp) prepared from the local
//   S-Graph: sends the distilled graph's changes since the last exchange, the free-space summary
//   when enough of it changed, the place clouds peers asked for, and the descriptor of every new
//   or significantly changed room (its room cloud is kept to answer requests for it). The
//   session never reads the local S-Graph: the node's SLAM thread prepares, the collab thread
//   ingests, and neither waits for the other's work (PublishNow does both in one thread).
// - Receive(type, bytes): decodes a peer's message (every decoder checks it; a malformed one
//   is counted by type and dropped). A room cloud request is answered at once.
// - Match(): proposes room pairs by Scan Context distance, requests the peer's room cloud for
//   fine alignment (modes with fine alignment), aligns when it has arrived, checks candidates
//   of anchored robot pairs against the merged estimate; then decides, per peer, whether and how
//   its map is merged (the merge rule, merge_rule.hpp: every hypothesis from the two maps'
//   corners, rooms and room matches, scored by the walls they lay on each other and refuted by
//   the free space each robot saw, kept only without a standing rival), logs every change of
//   decision with its evidence and rivals (MergeLog), and solves the collaborative graph when a
//   merge or a merged map changed. A merge that later evidence contradicts is undone.
// - The fallback (place_evidence.hpp): a pair the rule leaves undecided between two transforms
//   asks the peer for its points around a place that tells them apart, within a byte budget
//   per peer; the points set the loser aside. A peer's place request is queued, taken for the
//   next exchange (TakePlaceRequests: its cloud needs the map) and answered at its Ingest.
//
// Bounded: every store is sized at Init (capacities in CollabSessionConfig; the byte figure is
// in stats()); what allocates after Init is Ceres, in Match's fine alignments' solves and the
// collaborative graph's rebuild and solve. Full stores refuse with a counter: a peer beyond max_peers is ignored, a room
// beyond max_rooms gets no descriptor, a room cloud beyond max_room_points is not described,
// a peer's descriptor beyond max_peer_rooms is dropped, matches beyond max_matches_per_peer are
// dropped, the peer cloud cache evicts its oldest entry. Not thread-safe: the caller serialises.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <memory>
#include <span>

#include "msgraphs/base/expected.hpp"
#include "msgraphs/core/collab/alignment_search.hpp"
#include "msgraphs/core/collab/distiller.hpp"
#include "msgraphs/core/collab/free_space_summary.hpp"
#include "msgraphs/core/collab/merge_rule.hpp"
#include "msgraphs/core/collab/place_cloud.hpp"
#include "msgraphs/core/collab/place_evidence.hpp"
#include "msgraphs/core/collab/place_messages.hpp"
#include "msgraphs/core/collab/room_descriptor.hpp"
#include "msgraphs/core/collab/room_matcher.hpp"
#include "msgraphs/core/collab/room_messages.hpp"
#include "msgraphs/core/graph/collaborative_graph.hpp"
#include "msgraphs/core/slam/local_mapper.hpp"

namespace msgraphs::core {

struct CollabExchange;
struct CollabPublisherStats;

enum class CollabMessageType : std::uint8_t {
  kDistilledGraph = 0,
  kRoomDescriptor = 1,
  kRoomCloudRequest = 2,
  kRoomCloud = 3,
  kFreeSpace = 4,  ///< the free-space summary (free_space_codec.hpp)
  kPlaceRequest = 5,  ///< the merge decision's fallback (place_messages.hpp)
  kPlaceCloud = 6,
};
inline constexpr int kCollabMessageTypes = 7;
const char* CollabMessageTypeName(CollabMessageType type);

/// The paper's ablation modes.
struct CollabMode {
  bool walls = true;  ///< wall-to-wall factors beside room-to-room
  bool fine = true;   ///< fine alignment of room clouds before a match is accepted
};

/// Where the session's messages go. `to` is a robot id, or 0 for every peer.
class CollabOutbox {
 public:
  virtual ~CollabOutbox() = default;
  virtual void Send(CollabMessageType type,
                    std::uint16_t to,
                    std::span<const std::uint8_t> bytes) = 0;
};

struct CollabSessionConfig {
  std::uint16_t robot = 1;  ///< this robot's id (1..65535)
  CollabMode mode;
  CloudEncoding cloud_encoding = CloudEncoding::kQuantised16;
  float cloud_step_m = 0.01f;  ///< kQuantised16 / kQuantised8 step (kQuantised8: 0.05 fits rooms)
  /// kQuantised8: a room wider than 254 steps gets a coarser step, up to this; beyond it, 16 bits.
  float max_cloud_step_m = 0.125f;
  std::size_t max_peers = 8;
  std::size_t max_rooms = 64;           ///< own rooms with a descriptor and a room cloud
  std::size_t max_room_points = 12000;  ///< 2x the largest measured (5,800 at 0.2 m voxels)
  std::size_t max_peer_rooms = 128;     ///< descriptors held per peer
  std::size_t max_pending = 64;         ///< proposals waiting for a room cloud, per peer
  std::size_t max_matches_per_peer = 64;
  std::size_t cloud_cache = 16;  ///< peer room clouds kept for later proposals
  /// One exchange (collab_publisher.hpp) carries at most this many rebuilt rooms sharing this
  /// many points; a room beyond waits for the next exchange (CollabPublisherStats::rooms_deferred;
  /// a room is built only when max_room_points still fit). Every own room at once, 64 of the
  /// largest measured (5,800 points): a loop closure that moves every room rebuilds them all.
  /// About 9 MB per exchange; the node holds two.
  std::size_t rooms_per_exchange = 64;
  std::size_t room_points_per_exchange = 384000;
  std::size_t max_message_bytes = 1 << 20;
  /// A room's descriptor is rebuilt and sent again when its walls changed or its centre or size
  /// moved by more than this (its distilled entry follows every centimetre).
  double descriptor_resend_m = 0.3;
  /// From this many consistent matches on, a new candidate of that peer is checked against the
  /// merged estimate instead of by fine alignment: no room cloud crosses the radio. 0: from the
  /// merge on (the merge rule has placed the pair from walls and free space; a fine alignment
  /// would only refine it, and room clouds are half the bytes). Safe only because a corridor is
  /// tied across its axis alone (collaborative_graph.hpp): with its centroid tied in all
  /// directions, a pair held by room-to-room factors alone slid 7.6 m along a corridor.
  std::size_t anchored_matches = 0;
  double anchored_translation_m = 0.5;
  double anchored_rotation_rad = 0.1;
  /// A fine alignment measures the origin directly; its sigma (room clouds carry map error).
  double fine_origin_sigma_m = 0.03;
  double fine_origin_sigma_rad = 0.005;
  /// Match() calls after which an unanswered room cloud request is sent again.
  std::uint32_t request_retry_calls = 3;
  double wall_pair_angle_rad = 0.26;  ///< walls of matched rooms paired within this angle
  double wall_pair_offset_m = 0.3;    ///< and this offset after the match transform
  std::size_t max_wall_pairs = 512;   ///< matched wall pairs held for PlanePriors
  /// PlanePriors: the peer's wall covariance plus these floors for the origin's uncertainty.
  /// Not inflated: the peer's walls hold its own evidence only, never what this robot told it
  /// (rumour-free distillation, distiller.hpp), so feeding them back counts nothing twice.
  double feedback_sigma_floor_m = 0.01;
  double feedback_sigma_floor_rad = 0.005;
  /// A prior is fed back only while it agrees with this robot's own wall: the squared
  /// Mahalanobis distance of their difference (angle, angle, offset) under the two covariances
  /// summed stays within this bound, the chi-square 99 % quantile for 3 degrees of freedom.
  /// A prior beyond it says the origin it went through is off by more than the covariances
  /// allow (they do not hold the origin's own uncertainty); fed back, it bends the own map
  /// towards the error, the bent map goes out at the next exchange, and the peer's estimate
  /// follows it (docs/multi-robot.md, the ablation). 0 feeds every prior.
  double feedback_gate_chi2 = 11.345;
  DistillerConfig distiller;
  RoomDescriptorConfig descriptor;
  RoomMatchConfig matcher;
  FreeSpaceSummaryConfig free_space;
  /// The summary is sent again when this share of its cells changed since the last one sent.
  double free_space_resend_share = 0.02;
  AlignmentSearchConfig search;
  MergeRuleConfig merge;
  /// The fallback for pairs the rule leaves undecided (place_evidence.hpp).
  PlaceEvidenceConfig places;
  PlaceCloudConfig place_cloud;
  /// With fewer than two room matches the merge agrees with, the walls the merge lays on each
  /// other along at least this tie the maps (wall-to-wall factors).
  double wall_pair_min_overlap_m = 1.0;
  /// How well two robots' floors agree in height (each is its robot's base height below its
  /// first pose: Spot's body height varies by a few centimetres with its gait).
  double floor_sigma_m = 0.03;
  std::size_t max_log = 512;  ///< merge decisions kept (the oldest give way, counted)
  CollaborativeGraphConfig graph;
  Status Validate() const;
};

/// The evidence behind one hypothesis, as the decision saw it.
struct MergeEvidence {
  double agreement_m = 0, constraint_m = 0, conflict_m = 0;
  std::uint32_t votes = 0;
  std::uint8_t sources = 0;  ///< HypothesisSource bits
};

struct CollabPeerStats {
  std::uint16_t robot = 0;
  bool merged = false;
  std::uint32_t graph_version = 0;
  std::size_t walls = 0, rooms = 0, descriptors = 0;
  std::size_t matches = 0, consistent = 0;  ///< room matches, and those the merge agrees with
  bool has_free_space = false;
  /// The last decision: its verdict, the hypotheses scored (and refuted), the leader and the
  /// strongest standing rival (rival.agreement_m 0 without one).
  MergeVerdict verdict = MergeVerdict::kNoHypothesis;
  std::size_t hypotheses = 0, refuted = 0;
  bool undecided = false;  ///< not merged although a leader exists (a rival, too little, ...)
  bool symmetric = false, rival_from_symmetry = false;
  MergeEvidence leader, rival;
  std::size_t set_aside = 0, places = 0;  ///< the last decision's fallback (MergeDecision)
  std::uint64_t merges = 0, undone = 0, revised = 0;
  double first_merge_s = -1;  ///< the `now_s` of the Match that first merged it (-1: never)
  std::uint64_t bytes_received[kCollabMessageTypes] = {};
  std::uint64_t messages_received[kCollabMessageTypes] = {};
  std::uint64_t malformed = 0;   ///< rejected by a decoder, any type
  std::uint64_t graph_gaps = 0;  ///< deltas whose base this robot had not received
};

struct CollabSessionStats {
  std::size_t peers = 0, peers_peak = 0;
  std::size_t own_rooms = 0, own_rooms_peak = 0;
  std::size_t room_points_peak = 0;
  std::uint64_t bytes_sent[kCollabMessageTypes] = {};
  std::uint64_t messages_sent[kCollabMessageTypes] = {};
  std::uint64_t proposals = 0;      ///< Scan Context pairs below SC_th
  std::uint64_t rejected_fine = 0;  ///< fine alignment above ICP_th
  std::uint64_t checked_anchored = 0, rejected_anchored = 0;
  std::uint64_t rejected_consistency = 0;  ///< currently outside the consistent sets
  std::uint64_t accepted = 0;              ///< currently inside them
  std::uint64_t undecided = 0;  ///< peers with a leader but no merge (at the last decisions)
  std::uint64_t decisions = 0, merges = 0, undone = 0, revised = 0;
  std::uint64_t searches = 0, searches_truncated = 0;
  /// At the last solve: rooms tied room to room, walls tied wall to wall, fine alignments used.
  std::size_t solve_room_pairs = 0, solve_wall_pairs = 0, solve_origin_measurements = 0;
  /// At the last solve: rooms' room-to-wall edges (one per facing pair), and pairs refused
  /// (walls not facing each other across the room's centre).
  std::size_t solve_room_wall_edges = 0, solve_room_wall_refused = 0;
  std::uint64_t free_space_sent = 0, free_space_build_failures = 0;
  std::uint64_t log_entries = 0, log_dropped = 0;
  std::uint64_t solves = 0, solve_failures = 0;
  /// Over all solves: the collaborative graph's factors added, kept (measurement updated in
  /// place) and removed by their updates (CollaborativeGraph::last_update).
  std::uint64_t solve_factors_added = 0, solve_factors_kept = 0, solve_factors_removed = 0;
  /// Distillations with marginal wall covariances, and those that fell back to conditional ones.
  std::uint64_t marginal_updates = 0, marginal_failures = 0;
  /// Rumour-free distillation (CollabPublisherStats): solved without peers' priors, and failed.
  std::uint64_t own_evidence_jobs = 0, own_solve_failures = 0;
  std::uint64_t requests_sent = 0, requests_served = 0, requests_unknown = 0;
  /// The fallback: place clouds asked for, received, served; requests refused (a peer's byte
  /// budget spent, or the queue full), never answered, clouds not asked for; decisions weighed
  /// on place evidence and the transforms it set aside (place_decision.hpp).
  std::uint64_t place_requests_sent = 0, place_clouds_received = 0, place_requests_served = 0,
                place_requests_refused = 0, place_requests_unanswered = 0, place_clouds_unsolicited = 0,
                place_duels = 0, place_set_aside = 0;
  // Refusals of full stores (see the header comment).
  std::uint64_t rooms_deferred = 0;  ///< rooms left for a later exchange (collab_publisher.hpp)
  std::uint64_t peers_refused = 0, rooms_refused = 0, room_clouds_too_large = 0,
                descriptors_refused = 0, pending_refused = 0, matches_refused = 0,
                cache_evictions = 0, descriptors_mismatched = 0, encode_failures = 0,
                clouds_unsolicited = 0, wall_pairs_refused = 0;
  /// At the last PlanePriors call: priors held back by feedback_gate_chi2 (those written are
  /// its return value).
  std::size_t priors_gated = 0;
  /// Walls and rooms the collaborative graph could not hold at the last solve (its capacity, or
  /// a non-finite element).
  std::uint64_t graph_refused = 0;
  std::uint64_t cloud_encoding_fallbacks = 0;  ///< room clouds sent in 16 bits: too wide for 8
  std::uint64_t malformed = 0;
  std::size_t store_bytes = 0;
};

/// kMerged: a peer placed; kRevised: placed elsewhere; kUndone: contradicted, no longer placed;
/// kKept: still placed although a rival now stands (one that does not beat it); kUndecided: not
/// placed, for a new reason.
enum class MergeEvent : std::uint8_t { kMerged, kRevised, kUndone, kKept, kUndecided };
const char* ToString(MergeEvent event);

/// One change of a peer's merge decision, with its evidence and its strongest rival.
struct MergeLogEntry {
  std::uint64_t sequence = 0;  ///< 1, 2, ... over the session
  double now_s = 0;            ///< the caller's clock at that Match
  std::uint16_t peer = 0;
  MergeEvent event = MergeEvent::kUndecided;
  MergeVerdict verdict = MergeVerdict::kNoHypothesis;
  Eigen::Isometry3d T_self_peer = Eigen::Isometry3d::Identity();  ///< the leader's transform
  MergeEvidence leader, rival;
  bool has_rival = false, rival_from_symmetry = false, symmetric = false;
  std::size_t hypotheses = 0, refuted = 0;
  std::size_t set_aside = 0, places = 0;  ///< transforms set aside by place evidence, clouds weighed
};

/// What CollabSession::ExportReceived wrote.
struct CollabExportStats {
  std::size_t messages = 0, bytes = 0;
  std::size_t failed = 0;  ///< parts that did not encode (not exported: they come again live)
};

class CollabSession {
 public:
  CollabSession();
  ~CollabSession();
  CollabSession(const CollabSession&) = delete;
  CollabSession& operator=(const CollabSession&) = delete;

  /// `graph` gives the capacities of the local S-Graph; `floor_z_map_m` where the floor is in
  /// this robot's map frame (the map frame is the first base pose, so minus the base height).
  Status Init(const CollabSessionConfig& config, const SGraphConfig& graph, double floor_z_map_m);

  /// Sends what changed in the own map that `exchange` carries (prepared by a CollabPublisher
  /// initialised alike; its stats are copied into stats()); descriptors of rebuilt or unsent
  /// rooms; the place clouds it built. Its free-space summary is swapped in (the exchange gets
  /// the old one back). A distilled graph that does not encode returns the error after the rest
  /// went in. An exchange older than the last one is refused whole (exchanges out of order are
  /// the caller's bug: its rebuilt rooms are lost until they change again; its place requests'
  /// reservations are released and the peers ask again).
  Status Ingest(CollabExchange& exchange, const CollabPublisherStats& publisher, CollabOutbox& out);
  /// The peers' place requests the next exchange should answer, appended to `out` while it has
  /// room (the rest stay queued). A request beyond the peer's byte budget is refused and counted;
  /// a retry of a place answered, or taken and not yet ingested, is not taken again.
  void TakePlaceRequests(BoundedVector<PlaceRequest>& out);
  /// The next Ingest sends the whole graph and every descriptor again (a peer joined late).
  void ResendAll();

  /// A message from the link. Malformed ones return the decoder's error and are counted.
  Status Receive(CollabMessageType type, std::span<const std::uint8_t> bytes, CollabOutbox& out);

  /// What the session holds of its peers, as messages into `out` (to 0) that Receive files
  /// back into a new session alike: each peer's distilled graph whole, its room descriptors,
  /// its newest free-space summary (the parts the runtime checkpoint's journal keeps; room and
  /// place clouds are asked for again when needed). Matches and merges are not exported: Match
  /// decides them again from this evidence, as after a journal replay. The peers' message
  /// counters restart. Allocates nothing (encodes into the session's message buffer).
  CollabExportStats ExportReceived(CollabOutbox& out);

  /// Proposes, aligns, decides and solves; returns true when a room match was added. `now_s`
  /// (any clock of the caller's) stamps the decisions it logs.
  bool Match(CollabOutbox& out, double now_s = 0);

  const DistilledGraph& distilled() const;
  bool merged(std::uint16_t robot) const;
  /// Robot `robot`'s map frame in this robot's map frame (identity for this robot).
  Eigen::Isometry3d T_self_robot(std::uint16_t robot) const;
  /// The transform the merge decision placed `robot` with (before the collaborative graph refines
  /// it); identity when not merged.
  Eigen::Isometry3d T_self_robot_merge(std::uint16_t robot) const;
  /// The peer's distilled graph as received (nullptr for unknown robots).
  const DistilledGraph* peer_graph(std::uint16_t robot) const;
  /// Accepted matches with `robot` (the consistent set), into `out`; returns how many.
  std::size_t ConsistentMatches(std::uint16_t robot, std::span<RoomMatch> out) const;
  /// Every match with `robot` that passed its check (consistent or not).
  std::size_t AllMatches(std::uint16_t robot, std::span<RoomMatch> out) const;
  const CollaborativeGraph& collaborative_graph() const;
  /// Other robots' measurements of this robot's matched walls, through the merged origins: the
  /// priors that feed the collaborative estimate back into the local S-Graph
  /// (LocalMapper::SetPlanePriors). Those that disagree with the own wall beyond
  /// feedback_gate_chi2 are held back and counted (stats().priors_gated). Returns how many were
  /// written into `out`.
  std::size_t PlanePriors(std::span<PlanePrior> out) const;

  /// Merge decisions with sequence > `after`, oldest first, into `out`; returns how many. The log
  /// keeps the newest max_log entries (stats().log_dropped counts the rest).
  std::size_t MergeLog(std::uint64_t after, std::span<MergeLogEntry> out) const;
  /// This robot's free-space summary as last built (empty before the first Ingest).
  const FreeSpaceSummary& free_space() const;

  std::size_t peers() const;
  CollabPeerStats peer_stats(std::size_t index) const;
  const CollabSessionStats& stats() const;
  const CollabSessionConfig& config() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace msgraphs::core
