// SPDX-License-Identifier: MIT
// CollabSession: configuration, Init, what it publishes, and its accessors. What it receives is
// in collab_receive.cpp; room matching, the merge decision, the fallback's places and the
// collaborative graph in collab_room_matching.cpp, collab_merge.cpp, collab_places.cpp and
// collab_solve.cpp.
#include "msgraphs/core/collab/collab_session.hpp"

#include <algorithm>
#include <cmath>

#include "collab_session_impl.hpp"
#include "msgraphs/core/collab/collab_publisher.hpp"
#include "msgraphs/core/collab/distilled_codec.hpp"
#include "msgraphs/core/collab/free_space_codec.hpp"

namespace msgraphs::core {
const char* CollabMessageTypeName(CollabMessageType type) {
  switch (type) {
    case CollabMessageType::kDistilledGraph:
      return "distilled graph";
    case CollabMessageType::kRoomDescriptor:
      return "room descriptors";
    case CollabMessageType::kRoomCloudRequest:
      return "room cloud requests";
    case CollabMessageType::kRoomCloud:
      return "room clouds";
    case CollabMessageType::kFreeSpace:
      return "free space";
    case CollabMessageType::kPlaceRequest:
      return "place requests";
    case CollabMessageType::kPlaceCloud:
      return "place clouds";
  }
  return "unknown";
}

const char* ToString(MergeEvent event) {
  switch (event) {
    case MergeEvent::kMerged:
      return "merged";
    case MergeEvent::kRevised:
      return "revised";
    case MergeEvent::kUndone:
      return "undone";
    case MergeEvent::kKept:
      return "kept";
    case MergeEvent::kUndecided:
      return "undecided";
  }
  return "unknown";
}

Status CollabSessionConfig::Validate() const {
  if (robot == 0) return Error{Errc::kInvalidConfig, "collab session: robot id must be 1..65535"};
  if (max_peers < 1 || max_rooms < 1 || max_room_points < 100 || max_peer_rooms < 1 ||
      max_pending < 1 || max_matches_per_peer < 2 || max_matches_per_peer > 64 || cloud_cache < 1 ||
      max_message_bytes < 4096 || rooms_per_exchange < 1 || room_points_per_exchange < max_room_points) {
    return Error{Errc::kInvalidConfig,
                 "collab session: capacities must be positive (2..64 matches per peer; an exchange holds "
                 "the largest room cloud)"};
  }
  if (cloud_encoding != CloudEncoding::kFloat32 &&
      !(cloud_step_m > 0 && cloud_step_m < 1 && max_cloud_step_m >= cloud_step_m))
    return Error{Errc::kInvalidConfig, "collab session: cloud step must be in (0, 1) m"};
  if (!(descriptor_resend_m > 0) || !(anchored_translation_m > 0) || !(anchored_rotation_rad > 0) ||
      !(fine_origin_sigma_m > 0) || !(fine_origin_sigma_rad > 0) || request_retry_calls < 1 ||
      !(wall_pair_angle_rad > 0) || !(wall_pair_offset_m > 0) || max_wall_pairs < 1 ||
      !(feedback_sigma_floor_m > 0) ||
      !(feedback_sigma_floor_rad > 0)) {
    return Error{Errc::kInvalidConfig, "collab session: thresholds and sigmas must be positive"};
  }
  if (graph.max_robots <= max_peers)
    return Error{Errc::kInvalidConfig, "collab session: graph.max_robots must exceed max_peers"};
  if (auto s = distiller.Validate(); !s) return s;
  if (auto s = descriptor.Validate(); !s) return s;
  if (auto s = matcher.Validate(); !s) return s;
  if (auto s = free_space.Validate(); !s) return s;
  if (auto s = search.Validate(); !s) return s;
  if (auto s = merge.Validate(); !s) return s;
  if (auto s = places.Validate(); !s) return s;
  if (auto s = place_cloud.Validate(); !s) return s;
  if (PlaceCloudStep(places.radius_m) * 127.0f < places.radius_m)
    return Error{Errc::kInvalidConfig, "collab session: place radius does not fit the cloud's 8-bit units"};
  if (!(free_space_resend_share > 0 && free_space_resend_share <= 1) || !(wall_pair_min_overlap_m > 0) || !(floor_sigma_m > 0) || max_log < 1) {
    return Error{Errc::kInvalidConfig, "collab session: free-space share, pairing distances and log size"};
  }
  return graph.Validate();
}


CollabSession::Impl::Peer* CollabSession::Impl::FindOrAddPeer(std::uint16_t robot) {
  if (Peer* p = FindPeer(robot)) return p;
  for (Peer& p : peers) {
    if (p.used) continue;
    p.used = true;
    p.robot = robot;
    p.graph.Clear();  // sized at Init: a peer joining allocates nothing
    p.graph.robot = robot;
    p.rooms.clear();
    p.pending.clear();
    p.matches.clear();
    p.consistent_count = 0;
    p.merged = false;
    p.has_free = false;
    p.free_version = p.walls_version = p.symmetries_version = 0;
    p.decided_once = p.logged = false;
    p.decision = MergeDecision{};
    p.symmetries.clear();
    std::fill(p.tried.begin(), p.tried.end(), kUntried);
    for (SessionHeldPlace& held : p.places) held.used = false;
    p.places_version = p.decided_places = 0;
    p.places_asked.clear();
    p.place_pending = p.wants_place = false;
    p.place_pending_id = p.place_tries = p.next_place = 0;
    p.place_bytes_in = p.place_bytes_out = 0;
    p.place_served = p.place_in_flight = false;
    p.place_served_id = p.place_in_flight_id = 0;
    p.place_bytes_reserved = 0;
    p.stats = CollabPeerStats{};
    p.stats.robot = robot;
    ++stats.peers;
    stats.peers_peak = std::max(stats.peers_peak, stats.peers);
    return &p;
  }
  ++stats.peers_refused;
  return nullptr;
}

CollabSession::CollabSession() : impl_(std::make_unique<Impl>()) {}
CollabSession::~CollabSession() = default;

Status CollabSession::Init(const CollabSessionConfig& config_in,
                           const SGraphConfig& graph_config,
                           double floor_z_map_m) {
  CollabSessionConfig config = config_in;
  config.distiller.floor_z_m = floor_z_map_m;
  if (auto s = config.Validate(); !s) return s;
  if (!std::isfinite(floor_z_map_m))
    return Error{Errc::kInvalidConfig, "collab session: floor height not finite"};
  Impl& m = *impl_;
  m.config = config;
  m.floor_z_m = floor_z_map_m;
  if (graph_config.max_planes < 1) return Error{Errc::kInvalidConfig, "collab session: no planes"};
  m.own_graph.Init(config.distiller.max_walls, config.distiller.max_rooms);
  m.own_graph.robot = config.robot;
  if (auto s = m.matcher.Init(config.matcher); !s) return s;
  if (auto s = m.graph.Init(config.graph, config.robot); !s) return s;
  m.stats = CollabSessionStats{};
  m.sent_version = 0;
  m.calls = 0;
  m.own_walls_version = m.own_free_version = m.free_sent_version = m.own_symmetries_version = 0;
  m.sent_free_width = m.sent_free_height = 0;
  const ScanContextConfig& sc = config.descriptor.scan_context;
  m.descriptor_bytes = RoomDescriptorEncodedSize(sc.rings, sc.sectors);
  std::size_t bytes = 0;
  m.own = std::vector<Impl::OwnRoom>(config.max_rooms);
  for (Impl::OwnRoom& r : m.own) r.cloud.Init(config.max_room_points);
  bytes += config.max_rooms * (sizeof(Impl::OwnRoom) + config.max_room_points * 12);
  m.peers = std::vector<Impl::Peer>(config.max_peers);
  for (Impl::Peer& p : m.peers) {
    p.graph.Init(config.distiller.max_walls, config.distiller.max_rooms);
    p.rooms.Init(config.max_peer_rooms);
    p.descriptor_bytes.assign(config.max_peer_rooms * m.descriptor_bytes, 0);
    p.tried.assign(config.max_peer_rooms * config.max_rooms, kUntried);
    p.pending.Init(config.max_pending);
    p.matches.Init(config.max_matches_per_peer);
    p.consistent.assign(config.max_matches_per_peer, 0);
    p.places = std::vector<SessionHeldPlace>(config.places.max_places_per_peer);
    for (SessionHeldPlace& held : p.places) held.points.Init(config.place_cloud.max_points);
    p.places_asked.Init(config.places.max_asked_per_peer);
  }
  bytes += config.max_peers * config.places.max_places_per_peer *
           (sizeof(SessionHeldPlace) + config.place_cloud.max_points * 12);
  m.place_scorer.Init(config.place_cloud.max_points);
  m.place_chooser.Init(config.free_space.max_cells);
  m.place_queue.Init(config.places.max_requests_queued);
  m.place_scratch.Init(config.place_cloud.max_points);
  m.set_aside.Init(8);
  m.place_views.assign(config.places.max_places_per_peer, PlaceView{});
  bytes += 3 * config.place_cloud.max_points * 12 +
           config.free_space.max_cells * 9;
  bytes +=
      config.max_peers * (sizeof(Impl::Peer) + config.distiller.max_walls * sizeof(DistilledWall) +
                          config.distiller.max_rooms * sizeof(DistilledRoom) +
                          config.max_peer_rooms *
                              (sizeof(Impl::PeerRoom) + m.descriptor_bytes + config.max_rooms * 8) +
                          config.max_pending * sizeof(Impl::Pending) +
                          config.max_matches_per_peer * (sizeof(RoomMatch) + 4));
  m.cache = std::vector<Impl::CachedCloud>(config.cloud_cache);
  for (Impl::CachedCloud& c : m.cache) c.points.Init(config.max_room_points);
  bytes += config.cloud_cache * (sizeof(Impl::CachedCloud) + config.max_room_points * 12);
  m.buffer.assign(config.max_message_bytes, 0);
  m.delta.Init(config.distiller.max_walls, config.distiller.max_rooms);
  m.cloud_scratch.Init(config.descriptor.max_points);
  m.wall_pairs.Init(config.max_wall_pairs);
  bytes += config.max_message_bytes + config.descriptor.max_points * 12;
  // The merge decision: every map's walls and free space, the searches, the log.
  const std::size_t walls = config.distiller.max_walls;
  const std::size_t free_bytes = config.free_space.max_cells * 3 + config.free_space.max_openings * sizeof(Opening);
  if (auto s = m.own_walls.Init(walls); !s) return s;
  if (auto s = m.own_free.Init(config.free_space); !s) return s;
  m.sent_free.assign(config.free_space.max_cells, 0);
  m.own_symmetries.Init(config.merge.max_symmetries);
  for (Impl::Peer& p : m.peers) {
    if (auto s = p.walls.Init(walls); !s) return s;
    if (auto s = p.free.Init(config.free_space); !s) return s;
    p.symmetries.Init(config.merge.max_symmetries);
  }
  if (auto s = m.search.Init(config.search); !s) return s;
  // A map against itself has no channels (Search(..., self) skips them): no table for them.
  AlignmentSearchConfig self_search = config.search;
  self_search.min_channel_agreement_m = 0;
  self_search.max_channels = 0;
  self_search.max_channel_families = 16;
  if (auto s = m.symmetry_search.Init(self_search); !s) return s;
  m.seeds.Init(config.max_matches_per_peer);
  m.log.assign(config.max_log, MergeLogEntry{});
  m.log_sequence = 0;
  const std::size_t search_bytes =
      config.search.max_clusters * 56 + 2 * config.search.max_corners * 48 + config.search.max_hypotheses * sizeof(Hypothesis);
  bytes += config.search.max_channel_families * sizeof(AlignmentChannelFamily) +
           config.search.max_channels * sizeof(Hypothesis);
  bytes += (config.max_peers + 1) * (walls * sizeof(AlignWall) + free_bytes +
                                     config.merge.max_symmetries * sizeof(Hypothesis)) +
           config.free_space.max_cells + 2 * search_bytes + config.max_log * sizeof(MergeLogEntry);
  m.stats.store_bytes = bytes;
  return Ok();
}

Status CollabSession::Ingest(CollabExchange& x, const CollabPublisherStats& from, CollabOutbox& out) {
  Impl& m = *impl_;
  m.stats.marginal_updates = from.marginal_updates;
  m.stats.marginal_failures = from.marginal_failures;
  m.stats.own_evidence_jobs = from.own_evidence_jobs;
  m.stats.own_solve_failures = from.own_solve_failures;
  m.stats.free_space_build_failures = from.free_space_build_failures;
  m.stats.rooms_refused = from.rooms_refused;
  m.own_clouds_too_large = from.room_clouds_too_large;
  m.stats.room_clouds_too_large = m.own_clouds_too_large + m.peer_clouds_too_large;
  m.stats.rooms_deferred = from.rooms_deferred;
  m.stats.room_points_peak = from.room_points_peak;
  if (x.graph.version < m.own_graph.version) {
    m.ServePlaces(x, false, out);  // reservations released; the peers ask again
    return Error{Errc::kInvalidArgument, "collab session: an exchange older than the last one"};
  }
  DistilledGraph& g = m.own_graph;
  g.CopyFrom(x.graph);  // capacities sized alike
  g.robot = m.config.robot;
  Status result = Ok();
  if (g.version > m.sent_version) {
    // A graph that does not encode is counted and reported; the rest of the exchange still goes
    // in (its rooms are built only once).
    if (auto n = EncodeDistilled(g, m.sent_version, m.buffer); !n) {
      ++m.stats.encode_failures;
      result = n.error();
    } else {
      m.Send(out, CollabMessageType::kDistilledGraph, 0, *n);
      m.sent_version = g.version;
    }
  }
  if (x.free_built) {
    // Swapped, not copied: the exchange takes the old summary, which its next Prepare rebuilds.
    std::swap(m.own_free, x.free);
    x.free_built = false;
    m.IngestFreeSpace(out);
  }
  m.ServePlaces(x, true, out);
  for (const CollabExchange::Room& built : x.rooms) {
    Impl::OwnRoom* slot = m.FindOwn(built.id);
    if (slot == nullptr) {
      for (Impl::OwnRoom& r : m.own) {
        if (r.used) continue;
        slot = &r;
        break;
      }
      if (slot == nullptr) continue;  // as many slots as the publisher's: not reached
      ++m.stats.own_rooms;
      m.stats.own_rooms_peak = std::max(m.stats.own_rooms_peak, m.stats.own_rooms);
    }
    slot->used = true;
    slot->sent = false;
    slot->id = built.id;
    slot->version = built.version;
    slot->room = built.at_build;
    slot->at_build = built.at_build;
    slot->descriptor = built.descriptor;
    slot->cloud.clear();
    for (std::size_t i = 0; i < built.count; ++i) slot->cloud.push_back(x.room_points[built.first + i]);
  }
  for (const DistilledRoom& room : g.rooms) {
    Impl::OwnRoom* slot = m.FindOwn(room.id);
    if (slot == nullptr) continue;  // no descriptor yet
    slot->room = room;  // the latest estimate, for the frames
    if (slot->sent) continue;
    auto n =
        EncodeRoomDescriptor({m.config.robot, slot->id, slot->version}, slot->descriptor, m.buffer);
    if (!n) {
      ++m.stats.encode_failures;
      continue;
    }
    m.Send(out, CollabMessageType::kRoomDescriptor, 0, *n);
    slot->sent = true;
  }
  return result;
}

// The summary is rebuilt at every exchange and sent when enough of it changed.
void CollabSession::Impl::IngestFreeSpace(CollabOutbox& out) {
  bool changed = own_free.width() != sent_free_width || own_free.height() != sent_free_height ||
                 own_free.origin_m() != sent_free_origin || own_free.openings().size() != sent_free_openings;
  if (!changed) {
    const std::span<const std::uint8_t> cells = own_free.raw();
    std::size_t differ = 0;
    for (std::size_t i = 0; i < cells.size(); ++i) differ += cells[i] != sent_free[i] ? 1u : 0u;
    changed = static_cast<double>(differ) >= config.free_space_resend_share * static_cast<double>(cells.size());
  }
  if (!changed && free_sent_version > 0) return;
  ++own_free_version;
  auto n = EncodeFreeSpace({config.robot, own_free_version}, own_free, buffer);
  if (!n) {
    ++stats.encode_failures;
    return;
  }
  Send(out, CollabMessageType::kFreeSpace, 0, *n);
  ++stats.free_space_sent;
  free_sent_version = own_free_version;
  const std::span<const std::uint8_t> cells = own_free.raw();
  std::copy(cells.begin(), cells.end(), sent_free.begin());
  sent_free_width = own_free.width();
  sent_free_height = own_free.height();
  sent_free_origin = own_free.origin_m();
  sent_free_openings = own_free.openings().size();
}

void CollabSession::ResendAll() {
  impl_->sent_version = 0;
  impl_->free_sent_version = 0;
  for (Impl::OwnRoom& r : impl_->own) r.sent = false;
}

bool CollabSession::Match(CollabOutbox& out, double now_s) {
  Impl& m = *impl_;
  ++m.calls;
  m.now_s = now_s;
  bool changed = false;
  bool moved = false;  // a merged map changed since the last solve: its nodes moved
  for (Impl::Peer& p : m.peers) {
    if (!p.used) continue;
    changed = m.MatchPeer(p, out) || changed;
  }
  m.RefreshOwnMap();
  bool merges_changed = false;
  for (Impl::Peer& p : m.peers) {
    if (!p.used) continue;
    m.RefreshPeerMap(p);
    merges_changed = m.DecidePeer(p) || merges_changed;
    m.AskForPlace(p, out);
    moved = moved || (p.merged && p.graph.version != p.solved_version);
  }
  m.stats.accepted = m.stats.rejected_consistency = m.stats.undecided = 0;
  for (const Impl::Peer& p : m.peers) {
    if (!p.used) continue;
    m.stats.accepted += p.consistent_count;
    m.stats.rejected_consistency += p.matches.size() - p.consistent_count;
    m.stats.undecided += p.stats.undecided ? 1u : 0u;
  }
  moved = moved || (m.stats.solves > 0 && m.own_graph.version != m.solved_version);
  if (changed || moved || merges_changed) m.Solve();
  return changed;
}

const DistilledGraph& CollabSession::distilled() const { return impl_->own_graph; }

bool CollabSession::merged(std::uint16_t robot) const {
  if (robot == impl_->config.robot) return true;
  const Impl::Peer* p = impl_->FindPeer(robot);
  return p != nullptr && p->merged;
}

Eigen::Isometry3d CollabSession::T_self_robot(std::uint16_t robot) const {
  const Impl::Peer* p = impl_->FindPeer(robot);
  return p != nullptr && p->merged ? p->T_self_peer : Eigen::Isometry3d::Identity();
}

Eigen::Isometry3d CollabSession::T_self_robot_merge(std::uint16_t robot) const {
  const Impl::Peer* p = impl_->FindPeer(robot);
  return p != nullptr && p->merged ? p->T_merge.ToIsometry(impl_->floor_z_m - impl_->PeerFloor(*p))
                                   : Eigen::Isometry3d::Identity();
}

const DistilledGraph* CollabSession::peer_graph(std::uint16_t robot) const {
  const Impl::Peer* p = impl_->FindPeer(robot);
  return p == nullptr ? nullptr : &p->graph;
}

std::size_t CollabSession::ConsistentMatches(std::uint16_t robot, std::span<RoomMatch> out) const {
  const Impl::Peer* p = impl_->FindPeer(robot);
  if (p == nullptr) return 0;
  const std::size_t n = std::min(out.size(), p->consistent_count);
  for (std::size_t i = 0; i < n; ++i) out[i] = p->matches[p->consistent[i]];
  return n;
}

std::size_t CollabSession::AllMatches(std::uint16_t robot, std::span<RoomMatch> out) const {
  const Impl::Peer* p = impl_->FindPeer(robot);
  if (p == nullptr) return 0;
  const std::size_t n = std::min(out.size(), p->matches.size());
  for (std::size_t i = 0; i < n; ++i) out[i] = p->matches[i];
  return n;
}

const CollaborativeGraph& CollabSession::collaborative_graph() const { return impl_->graph; }

std::size_t CollabSession::MergeLog(std::uint64_t after, std::span<MergeLogEntry> out) const {
  const Impl& m = *impl_;
  const std::uint64_t kept = std::min<std::uint64_t>(m.log_sequence, m.log.size());
  std::uint64_t first = std::max<std::uint64_t>(after + 1, m.log_sequence - kept + 1);
  std::size_t n = 0;
  for (std::uint64_t s = first; s <= m.log_sequence && n < out.size(); ++s)
    out[n++] = m.log[static_cast<std::size_t>((s - 1) % m.log.size())];
  return n;
}

const FreeSpaceSummary& CollabSession::free_space() const { return impl_->own_free; }

std::size_t CollabSession::peers() const {
  std::size_t n = 0;
  for (const Impl::Peer& p : impl_->peers) n += p.used ? 1 : 0;
  return n;
}

CollabPeerStats CollabSession::peer_stats(std::size_t index) const {
  std::size_t n = 0;
  for (const Impl::Peer& p : impl_->peers) {
    if (!p.used) continue;
    if (n++ != index) continue;
    CollabPeerStats s = p.stats;
    s.merged = p.merged;
    s.graph_version = p.graph.version;
    s.walls = p.graph.walls.size();
    s.rooms = p.graph.rooms.size();
    s.descriptors = p.rooms.size();
    s.matches = p.matches.size();
    s.consistent = p.consistent_count;
    s.has_free_space = p.has_free;
    return s;
  }
  return {};
}

const CollabSessionStats& CollabSession::stats() const { return impl_->stats; }
const CollabSessionConfig& CollabSession::config() const { return impl_->config; }

}  // namespace msgraphs::core