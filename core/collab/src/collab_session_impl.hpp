// SPDX-License-Identifier: MIT
// CollabSession's state, shared by its parts: messages (collab_session.cpp), room matching
// (collab_room_matching.cpp), the merge decision (collab_merge.cpp) and the collaborative graph
// (collab_solve.cpp). Private to core_collab.
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

#include "msgraphs/core/collab/collab_publisher.hpp"
#include "msgraphs/core/collab/collab_session.hpp"
#include "msgraphs/core/collab/place_decision.hpp"
#include "msgraphs/core/collab/place_messages.hpp"

namespace msgraphs::core {

inline constexpr std::uint64_t kUntried = std::numeric_limits<std::uint64_t>::max();
inline constexpr double kQuarterTurn = 1.5707963267948966;

// A peer's room descriptor held (its bytes are in the peer's pool).
struct SessionPeerRoom {
  std::uint32_t id = 0, version = 0;
};
// A wall of ours paired with a peer's wall through a merge.
struct SessionWallPair {
  std::uint32_t own_wall = 0, peer_wall = 0;
  std::uint16_t peer = 0;
};
// A Scan Context proposal waiting for the peer's room cloud.
struct SessionPending {
  std::uint32_t own_room = 0, own_version = 0, peer_room = 0, peer_version = 0;
  float sc_distance = 1, yaw_rad = 0;
  std::uint64_t requested_call = 0;
};

// A peer's place cloud held for the fallback (collab_places.cpp).
struct SessionHeldPlace {
  bool used = false;
  std::uint32_t place = 0;
  Eigen::Vector2d centre_m = Eigen::Vector2d::Zero();  // the peer's map frame
  std::uint64_t stamp = 0;
  BoundedVector<Eigen::Vector3f> points;  // relative to the centre and the peer's floor
};

struct CollabSession::Impl {
  CollabSessionConfig config;
  double floor_z_m = 0;
  DistilledGraph own_graph;  // this robot's, as the last exchange brought it
  RoomMatcher matcher;
  CollaborativeGraph graph;
  CollabSessionStats stats;
  std::uint32_t sent_version = 0;
  std::uint32_t solved_version = 0;  // our distilled graph's version at the last solve
  std::uint64_t calls = 0;
  double now_s = 0;
  std::size_t descriptor_bytes = 0;  // our descriptor shape on the wire: peers' must match

  struct OwnRoom {
    bool used = false, sent = false;
    std::uint32_t id = 0, version = 0;  // version: the room's when its descriptor was built
    DistilledRoom room, at_build;
    ScanContext descriptor;
    BoundedVector<Eigen::Vector3f> cloud;
  };
  std::vector<OwnRoom> own;

  // This robot's map as the merge decision sees it: walls, free space, its own symmetries.
  WallIndex own_walls;
  std::uint32_t own_walls_version = 0;
  FreeSpaceSummary own_free;
  std::uint32_t own_free_version = 0;  // bumped at each Build that changed it
  std::vector<std::uint8_t> sent_free;  // the cells last sent
  int sent_free_width = 0, sent_free_height = 0;
  std::size_t sent_free_openings = 0;
  Eigen::Vector2d sent_free_origin = Eigen::Vector2d::Zero();
  std::uint32_t free_sent_version = 0;
  BoundedVector<Hypothesis> own_symmetries;
  std::uint32_t own_symmetries_version = 0;

  using PeerRoom = SessionPeerRoom;
  using Pending = SessionPending;
  struct Peer {
    bool used = false;
    std::uint16_t robot = 0;
    DistilledGraph graph;
    BoundedVector<PeerRoom> rooms;
    std::vector<std::uint8_t> descriptor_bytes;  // rooms[i] at i * descriptor_bytes
    std::vector<std::uint64_t> tried;            // [peer room slot][own room slot]
    BoundedVector<Pending> pending;
    BoundedVector<RoomMatch> matches;
    std::vector<std::uint32_t> consistent;  // matches the merge agrees with
    std::size_t consistent_count = 0;
    // The peer's map for the merge decision.
    WallIndex walls;
    std::uint32_t walls_version = 0;
    FreeSpaceSummary free;
    bool has_free = false;
    std::uint32_t free_version = 0;
    BoundedVector<Hypothesis> symmetries;
    std::uint32_t symmetries_version = 0;
    // What the last decision saw (skipped when nothing changed) and what it decided.
    std::uint32_t decided_own = 0, decided_peer = 0, decided_own_free = 0, decided_free = 0;
    std::size_t decided_matches = 0;
    bool decided_once = false, logged = false;
    MergeDecision decision;
    bool merged = false;
    PlanarTransform T_merge;  // the merge's hypothesis (planar)
    // The leader awaiting confirmation (MergeRuleConfig::confirmations) and in how many
    // consecutive decisions it led.
    PlanarTransform pending_T;
    std::uint32_t pending_count = 0;
    // The graphs (own, the peer's) it last led on: only a decision on a newer graph confirms.
    std::uint32_t pending_own = 0, pending_peer = 0;
    // Its constraint (metres of wall on wall in its weakest direction) when it last counted: a
    // confirmation needs more.
    double pending_constraint_m = 0;
    // The fallback (collab_places.cpp): its place clouds, the places asked for, the request
    // outstanding, the bytes each way, and the two transforms the last decision could not
    // tell apart (a place is asked for them).
    std::vector<SessionHeldPlace> places;
    std::uint32_t places_version = 0, decided_places = 0;
    BoundedVector<Eigen::Vector2d> places_asked;
    bool place_pending = false, wants_place = false;
    std::uint32_t place_pending_id = 0, place_tries = 0, next_place = 0;
    std::uint64_t place_requested_call = 0;
    std::uint64_t place_bytes_in = 0, place_bytes_out = 0;
    std::uint64_t place_bytes_reserved = 0;  // requests taken for the next exchange, at the largest
    bool place_served = false;  // the last place this peer asked for was answered
    std::uint32_t place_served_id = 0;
    bool place_in_flight = false;  // a place taken for an exchange not ingested yet
    std::uint32_t place_in_flight_id = 0;
    PlanarTransform duel_first, duel_second;
    std::uint32_t solved_version = 0;  // its graph's version at the last solve
    Eigen::Isometry3d T_self_peer = Eigen::Isometry3d::Identity();
    CollabPeerStats stats;
  };
  std::vector<Peer> peers;

  struct CachedCloud {
    bool used = false;
    std::uint16_t robot = 0;
    std::uint32_t room = 0, version = 0;
    std::uint64_t stamp = 0;
    BoundedVector<Eigen::Vector3f> points;
  };
  std::vector<CachedCloud> cache;
  std::uint64_t cache_clock = 0;

  // The merge decisions log (a ring of the newest max_log).
  std::vector<MergeLogEntry> log;
  std::uint64_t log_sequence = 0;

  // Scratch (sized at Init).
  std::vector<std::uint8_t> buffer;
  DistilledGraph delta;
  BoundedVector<Eigen::Vector3f> cloud_scratch;
  ScanContext descriptor_scratch;
  BoundedVector<SessionWallPair> wall_pairs;
  AlignmentSearch search;           // robot pairs
  AlignmentSearch symmetry_search;  // one map with itself
  BoundedVector<PlanarTransform> seeds;
  bool solve_needed = false;
  // The fallback: requests from peers awaiting the next Publish, the builder, the scorer.
  BoundedVector<PlaceRequest> place_queue;
  PlaceScorer place_scorer;
  PlaceChooser place_chooser;
  BoundedVector<Eigen::Vector3f> place_scratch;
  BoundedVector<PlanarTransform> set_aside;
  std::vector<PlaceView> place_views;  // the held places of one peer, for a decision
  std::uint64_t place_clock = 0;
  // Own room clouds too large to describe (the publisher's count) and peers' too large to hold
  // (Receive's): stats().room_clouds_too_large is their sum.
  std::uint64_t own_clouds_too_large = 0, peer_clouds_too_large = 0;

  Peer* FindPeer(std::uint16_t robot) {
    for (Peer& p : peers) {
      if (p.used && p.robot == robot) return &p;
    }
    return nullptr;
  }
  const Peer* FindPeer(std::uint16_t robot) const { return const_cast<Impl*>(this)->FindPeer(robot); }
  Peer* FindOrAddPeer(std::uint16_t robot);
  OwnRoom* FindOwn(std::uint32_t id) {
    for (OwnRoom& r : own) {
      if (r.used && r.id == id) return &r;
    }
    return nullptr;
  }
  CachedCloud* FindCached(std::uint16_t robot, std::uint32_t room, std::uint32_t version) {
    for (CachedCloud& c : cache) {
      if (c.used && c.robot == robot && c.room == room && c.version == version) return &c;
    }
    return nullptr;
  }
  std::size_t PeerRoomSlot(const Peer& p, std::uint32_t id) const {
    for (std::size_t i = 0; i < p.rooms.size(); ++i) {
      if (p.rooms[i].id == id) return i;
    }
    return p.rooms.size();
  }
  double PeerFloor(const Peer& p) const {
    // Before the peer's floor arrives, the same robot model stands at the same height.
    return p.graph.has_floor ? p.graph.floor_z_m : floor_z_m;
  }

  void Send(CollabOutbox& out, CollabMessageType type, std::uint16_t to, std::size_t n) {
    const auto t = static_cast<int>(type);
    stats.bytes_sent[t] += n;
    ++stats.messages_sent[t];
    out.Send(type, to, std::span<const std::uint8_t>(buffer.data(), n));
  }

  // collab_session.cpp
  void IngestFreeSpace(CollabOutbox& out);
  // collab_room_matching.cpp
  void SendRequest(CollabOutbox& out, const Peer& p, const Pending& q);
  bool AddMatch(Peer& p, const RoomMatch& m);
  bool Align(Peer& p, const Pending& q, const OwnRoom& mine, const DistilledRoom& theirs, const CachedCloud& cloud);
  bool MatchPeer(Peer& p, CollabOutbox& out);
  // collab_merge.cpp
  void RefreshOwnMap();
  void RefreshPeerMap(Peer& p);
  bool DecidePeer(Peer& p);  // true when the merge (or its transform) changed
  void Log(const Peer& p, MergeEvent event);
  // collab_solve.cpp
  void Solve();
  // collab_places.cpp
  Status ReceivePlaceRequest(std::span<const std::uint8_t> bytes);
  Status ReceivePlaceCloud(std::span<const std::uint8_t> bytes);
  void ServePlaces(const CollabExchange& x, bool send, CollabOutbox& out);
  void WeighPlaces(Peer& p, MergeInputs& in, MergeDecision& d);
  void AskForPlace(Peer& p, CollabOutbox& out);
};

}  // namespace msgraphs::core
