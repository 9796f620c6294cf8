// SPDX-License-Identifier: MIT
// The half of a robot's collaborative side that reads its own map: distillation, room clouds
// and descriptors, the free-space summary and the place clouds peers asked for. It runs where
// the map lives (the node's SLAM thread) and hands its result, a CollabExchange, to the
// CollabSession (the collab thread), which encodes and sends it and matches against it.
//
// Why two objects: the session's Match runs fine alignments, the merge decision and the
// collaborative solve, seconds at worst; had the SLAM thread published through the session, it
// would have waited for them (issue 19). The publisher shares no state with the session: what
// crosses is the exchange, a value sized at Init that the caller passes between threads
// (runtime/pipeline: two exchanges, swapped through a mailbox; CollabSession::Publish-like use
// in one thread: PublishNow below).
//
// Bounded: every store is sized at Init. Prepare allocates through Ceres only (the walls'
// marginal covariances, Distiller) when it computes them itself; with MarginalsTiming::
// kBackground and the marginals job run by another thread (marginals_job()), or without
// marginals, it allocates nothing (counted: collab_publisher_test without marginals,
// distiller_test for the distillation with background marginals). A room whose cloud does not fit the exchange waits for the next one
// (stats().rooms_deferred); a room beyond max_rooms gets no descriptor (rooms_refused).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

#include "msgraphs/base/bounded_vector.hpp"
#include "msgraphs/base/expected.hpp"
#include "msgraphs/core/collab/collab_session.hpp"

namespace msgraphs::core {

/// A room whose descriptor was (re)built: its cloud is room_points[first, first + count) of its
/// exchange.
struct ExchangedRoom {
  std::uint32_t id = 0, version = 0;
  DistilledRoom at_build;
  ScanContext descriptor;
  std::size_t first = 0, count = 0;
};
/// A place cloud for a peer's request: place_points[first, first + count) of its exchange (none
/// stored there: an empty cloud says so).
struct ExchangedPlace {
  PlaceRequest request;
  float radius_m = 0;
  std::size_t first = 0, count = 0;
};

/// One exchange's worth of the own map, from the publisher to the session.
struct CollabExchange {
  using Room = ExchangedRoom;
  using Place = ExchangedPlace;

  /// In: the peers' place requests to answer (CollabSession::TakePlaceRequests), filled by the
  /// caller before Prepare; Prepare leaves them and clears the rest.
  BoundedVector<PlaceRequest> requests;

  DistilledGraph graph;
  bool graph_changed = false;
  FreeSpaceSummary free;
  bool free_built = false;
  BoundedVector<Room> rooms;
  BoundedVector<Eigen::Vector3f> room_points;
  BoundedVector<Place> places;
  BoundedVector<Eigen::Vector3f> place_points;

  /// Sized for `config` (the session's): rooms_per_exchange rooms sharing
  /// room_points_per_exchange points, max_requests_queued places (about 9 MB with the defaults).
  Status Init(const CollabSessionConfig& config);
  void Clear();  ///< all but `requests`
};

struct CollabPublisherStats {
  std::uint64_t prepares = 0;
  std::uint64_t marginal_updates = 0, marginal_failures = 0;
  std::uint64_t marginals_run_at_prepare = 0;   ///< kBackground: nobody had claimed the job
  std::uint64_t marginals_not_ready = 0;        ///< kBackground: its runner was not done
  std::uint64_t walls_awaiting_marginals = 0;   ///< summed over exchanges (Distiller::Stats)
  /// Rumour-free distillation (Distiller::Stats): jobs that left peers' priors out, own-evidence
  /// solves that failed, rooms held back for want of an own estimate (summed).
  std::uint64_t own_evidence_jobs = 0, own_solve_unconverged = 0, own_solve_failures = 0;
  std::uint64_t walls_awaiting_estimates = 0, rooms_awaiting_estimates = 0;
  std::uint64_t walls_unobserved = 0;  ///< not shared: nothing measures them any more (summed)
  std::uint64_t free_space_build_failures = 0;
  std::uint64_t rooms_refused = 0, room_clouds_too_large = 0, rooms_deferred = 0;
  std::size_t room_points_peak = 0;
  std::uint64_t places_built = 0;
};

class CollabPublisher {
 public:
  /// The same configuration, S-Graph capacities and floor height as the session's Init.
  Status Init(const CollabSessionConfig& config, const SGraphConfig& graph, double floor_z_map_m);

  /// Distils `mapper`'s graph, rebuilds the descriptors of new or significantly changed rooms,
  /// builds the free-space summary and a place cloud for each of `io.requests`, into `io`.
  /// `marginals`: when the walls' marginal covariances are computed (Distiller).
  void Prepare(const LocalMapper& mapper,
               CollabExchange& io,
               MarginalsTiming marginals = MarginalsTiming::kNow);

  /// The first step of a kBackground Prepare (Distiller::BeginMarginals): the walls'
  /// marginals job for the map as it is now, for marginals_job()'s runner; Prepare once
  /// marginals_ready().
  bool BeginMarginals(const LocalMapper& mapper) {
    return distiller_.BeginMarginals(mapper.graph());
  }
  bool marginals_ready() const { return distiller_.marginals_ready(); }
  /// The walls' marginals job BeginMarginals began, until it is done: for another thread to
  /// take (TryClaim, then Run); nullptr otherwise.
  SGraphSolveJob* marginals_job() { return distiller_.marginals_job(); }

  /// The distilled graph as last prepared.
  const DistilledGraph& graph() const { return distiller_.graph(); }
  const CollabPublisherStats& stats() const { return stats_; }

 private:
  struct Built {
    bool used = false, stale = true;
    std::uint32_t id = 0, version = 0;
    DistilledRoom at_build;
  };
  void PrepareRooms(const LocalMapper& mapper, CollabExchange& out);

  CollabSessionConfig config_;
  double floor_z_m_ = 0;
  Distiller distiller_;
  RoomDescriptorBuilder builder_;
  PlaceCloudBuilder place_builder_;
  std::vector<Built> built_;
  BoundedVector<Eigen::Vector3f> cloud_scratch_, place_scratch_;
  ScanContext descriptor_scratch_;
  CollabPublisherStats stats_;
};

/// Publisher and session in one thread (msgraphs_collab, tests): the session's place requests
/// into `exchange`, prepared, and ingested at once.
Status PublishNow(const LocalMapper& mapper,
                  CollabPublisher& publisher,
                  CollabExchange& exchange,
                  CollabSession& session,
                  CollabOutbox& out,
                  MarginalsTiming marginals = MarginalsTiming::kNow);

}  // namespace msgraphs::core
