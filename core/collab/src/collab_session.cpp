// SPDX-License-Identifier: MIT
#include "msgraphs/core/collab/collab_session.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <vector>

#include "msgraphs/core/collab/distilled_codec.hpp"

namespace msgraphs::core {
namespace {

constexpr std::uint64_t kUntried = std::numeric_limits<std::uint64_t>::max();
constexpr double kQuarterTurn = 1.5707963267948966;
// Competing consistent sets of matches compared per peer, largest first, single matches
// included (a row of identical rooms gives two or three sets and a few single matches).
constexpr std::size_t kMaxHypotheses = 8;

bool SignificantlyChanged(const DistilledRoom& a, const DistilledRoom& b, double threshold_m) {
  return a.walls != b.walls || a.shape != b.shape || (a.centre - b.centre).norm() > threshold_m ||
         std::fabs(a.size_x_m - b.size_x_m) > threshold_m ||
         std::fabs(a.size_y_m - b.size_y_m) > threshold_m;
}

// A peer's room descriptor held (its bytes are in the peer's pool).
struct SessionPeerRoom {
  std::uint32_t id = 0, version = 0;
};
// A wall of ours paired with a peer's wall through an accepted match.
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

}  // namespace

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
  }
  return "unknown";
}

Status CollabSessionConfig::Validate() const {
  if (robot == 0) return Error{Errc::kInvalidConfig, "collab session: robot id must be 1..65535"};
  if (max_peers < 1 || max_rooms < 1 || max_room_points < 100 || max_peer_rooms < 1 ||
      max_pending < 1 || max_matches_per_peer < 2 || max_matches_per_peer > 64 || cloud_cache < 1 ||
      max_message_bytes < 4096) {
    return Error{Errc::kInvalidConfig,
                 "collab session: capacities must be positive (2..64 matches per peer)"};
  }
  if (cloud_encoding != CloudEncoding::kFloat32 &&
      !(cloud_step_m > 0 && cloud_step_m < 1 && max_cloud_step_m >= cloud_step_m))
    return Error{Errc::kInvalidConfig, "collab session: cloud step must be in (0, 1) m"};
  if (!(descriptor_resend_m > 0) || !(anchored_translation_m > 0) || !(anchored_rotation_rad > 0) ||
      !(fine_origin_sigma_m > 0) || !(fine_origin_sigma_rad > 0) || request_retry_calls < 1 ||
      !(wall_pair_angle_rad > 0) || !(wall_pair_offset_m > 0) || max_wall_pairs < 1 ||
      !(feedback_inflation >= 1) || !(feedback_sigma_floor_m > 0) ||
      !(feedback_sigma_floor_rad > 0)) {
    return Error{Errc::kInvalidConfig, "collab session: thresholds and sigmas must be positive"};
  }
  if (graph.max_robots <= max_peers)
    return Error{Errc::kInvalidConfig, "collab session: graph.max_robots must exceed max_peers"};
  if (auto s = distiller.Validate(); !s) return s;
  if (auto s = descriptor.Validate(); !s) return s;
  if (auto s = matcher.Validate(); !s) return s;
  if (auto s = hypotheses.Validate(); !s) return s;
  return graph.Validate();
}

struct CollabSession::Impl {
  CollabSessionConfig config;
  double floor_z_m = 0;
  Distiller distiller;
  RoomDescriptorBuilder builder;
  RoomMatcher matcher;
  CollaborativeGraph graph;
  CollabSessionStats stats;
  std::uint32_t sent_version = 0;
  std::uint32_t solved_version = 0;  // our distilled graph's version at the last solve
  std::uint64_t calls = 0;
  std::size_t descriptor_bytes = 0;  // our descriptor shape on the wire: peers' must match

  struct OwnRoom {
    bool used = false, sent = false;
    std::uint32_t id = 0, version = 0;  // version: the room's when its descriptor was built
    DistilledRoom room, at_build;
    ScanContext descriptor;
    BoundedVector<Eigen::Vector3f> cloud;
  };
  std::vector<OwnRoom> own;

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
    std::vector<std::uint32_t> consistent;
    std::size_t consistent_count = 0;
    std::size_t hypotheses = 0;  // competing consistent sets at the last solve
    bool undecided = false;      // ... and none clearly better
    double agreement_m[2] = {};  // wall agreement of the chosen set and of its best rival
    std::size_t hypothesis_matches[2] = {};  // and their sizes
    bool merged = false;
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

  // Scratch (sized at Init).
  std::vector<std::uint8_t> buffer;
  DistilledGraph delta;
  BoundedVector<Eigen::Vector3f> cloud_scratch;
  ScanContext descriptor_scratch;
  std::vector<std::uint32_t> clique;
  BoundedVector<SessionWallPair> wall_pairs;

  Peer* FindPeer(std::uint16_t robot) {
    for (Peer& p : peers) {
      if (p.used && p.robot == robot) return &p;
    }
    return nullptr;
  }
  Peer* FindOrAddPeer(std::uint16_t robot) {
    if (Peer* p = FindPeer(robot)) return p;
    for (Peer& p : peers) {
      if (p.used) continue;
      p.used = true;
      p.robot = robot;
      p.graph.Init(config.distiller.max_walls, config.distiller.max_rooms);
      p.graph.robot = robot;
      p.rooms.clear();
      p.pending.clear();
      p.matches.clear();
      p.consistent_count = 0;
      p.hypotheses = 0;
      p.undecided = false;
      p.merged = false;
      std::fill(p.tried.begin(), p.tried.end(), kUntried);
      p.stats = CollabPeerStats{};
      p.stats.robot = robot;
      ++stats.peers;
      stats.peers_peak = std::max(stats.peers_peak, stats.peers);
      return &p;
    }
    ++stats.peers_refused;
    return nullptr;
  }
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

  void Send(CollabOutbox& out, CollabMessageType type, std::uint16_t to, std::size_t n) {
    const auto t = static_cast<int>(type);
    stats.bytes_sent[t] += n;
    ++stats.messages_sent[t];
    out.Send(type, to, std::span<const std::uint8_t>(buffer.data(), n));
  }

  void SendRequest(CollabOutbox& out, const Peer& p, const Pending& q) {
    auto n = EncodeRoomCloudRequest({config.robot, p.robot, q.peer_room, q.peer_version}, buffer);
    if (!n) {
      ++stats.encode_failures;
      return;
    }
    ++stats.requests_sent;
    Send(out, CollabMessageType::kRoomCloudRequest, p.robot, *n);
  }

  bool AddMatch(Peer& p, const RoomMatch& m) {
    if (!p.matches.try_push_back(m)) {
      ++stats.matches_refused;
      return false;
    }
    return true;
  }

  // The pending proposal's clouds are both here: align them.
  bool Align(Peer& p,
             const Pending& q,
             const OwnRoom& mine,
             const DistilledRoom& theirs,
             const CachedCloud& cloud) {
    RoomMatch m;
    m.robot_a = config.robot;
    m.robot_b = p.robot;
    m.room_a = q.own_room;
    m.room_b = q.peer_room;
    m.sc_distance = q.sc_distance;
    const Eigen::Isometry3d T_ma_ra = RoomFrame(mine.at_build, floor_z_m);
    const Eigen::Isometry3d T_mb_rb = RoomFrame(theirs, PeerFloor(p));
    if (!matcher.FineAlign(mine.cloud.span(), T_ma_ra, cloud.points.span(), T_mb_rb,
                           static_cast<double>(q.yaw_rad), m)) {
      ++stats.rejected_fine;
      return false;
    }
    return AddMatch(p, m);
  }

  double PeerFloor(const Peer& p) const {
    // Before the peer's floor arrives, the same robot model stands at the same height.
    return p.graph.has_floor ? p.graph.floor_z_m : floor_z_m;
  }

  bool MatchPeer(Peer& p, CollabOutbox& out);
  // The accepted set of p's matches into p.consistent (MatchHypotheses, ChooseHypothesis).
  std::size_t ChooseConsistent(Peer& p, const DistilledGraph& mine);
  void Solve();
};

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
  if (auto s = m.distiller.Init(config.robot, graph_config, config.distiller); !s) return s;
  if (auto s = m.builder.Init(config.descriptor); !s) return s;
  if (auto s = m.matcher.Init(config.matcher); !s) return s;
  if (auto s = m.graph.Init(config.graph, config.robot); !s) return s;
  m.stats = CollabSessionStats{};
  m.sent_version = 0;
  m.calls = 0;
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
  }
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
  m.clique.assign(config.max_matches_per_peer, 0);
  m.wall_pairs.Init(config.max_wall_pairs);
  bytes += config.max_message_bytes + config.descriptor.max_points * 12;
  m.stats.store_bytes = bytes;
  return Ok();
}

Status CollabSession::Publish(const LocalMapper& mapper, CollabOutbox& out) {
  Impl& m = *impl_;
  m.distiller.Update(mapper.graph(), mapper.plane_mapper());
  m.stats.marginal_updates = m.distiller.stats().marginal_updates;
  m.stats.marginal_failures = m.distiller.stats().marginal_failures;
  const DistilledGraph& g = m.distiller.graph();
  if (g.version > m.sent_version) {
    auto n = EncodeDistilled(g, m.sent_version, m.buffer);
    if (!n) {
      ++m.stats.encode_failures;
      return n.error();
    }
    m.Send(out, CollabMessageType::kDistilledGraph, 0, *n);
    m.sent_version = g.version;
  }
  for (const DistilledRoom& room : g.rooms) {
    Impl::OwnRoom* slot = m.FindOwn(room.id);
    if (slot != nullptr) {
      slot->room = room;  // the latest estimate, for the frames
      if (!SignificantlyChanged(slot->at_build, room, m.config.descriptor_resend_m)) {
        if (slot->sent) continue;
      } else {
        slot->sent = false;
        slot->version = 0;  // rebuild below
      }
    } else {
      for (Impl::OwnRoom& r : m.own) {
        if (r.used) continue;
        slot = &r;
        break;
      }
      if (slot == nullptr) {
        ++m.stats.rooms_refused;
        continue;
      }
    }
    if (slot->version == 0 || !slot->used) {
      // New or changed: rebuild its cloud and descriptor.
      if (!m.builder.Build(mapper, room, m.cloud_scratch, m.descriptor_scratch)) continue;
      m.stats.room_points_peak = std::max(m.stats.room_points_peak, m.cloud_scratch.size());
      if (m.cloud_scratch.size() > slot->cloud.capacity()) {
        ++m.stats.room_clouds_too_large;
        continue;
      }
      if (!slot->used) {
        ++m.stats.own_rooms;
        m.stats.own_rooms_peak = std::max(m.stats.own_rooms_peak, m.stats.own_rooms);
      }
      slot->used = true;
      slot->id = room.id;
      slot->version = std::max<std::uint32_t>(room.version, 1);
      slot->room = room;
      slot->at_build = room;
      slot->descriptor = m.descriptor_scratch;
      slot->cloud.clear();
      for (const Eigen::Vector3f& p : m.cloud_scratch) slot->cloud.push_back(p);
    }
    auto n =
        EncodeRoomDescriptor({m.config.robot, slot->id, slot->version}, slot->descriptor, m.buffer);
    if (!n) {
      ++m.stats.encode_failures;
      continue;
    }
    m.Send(out, CollabMessageType::kRoomDescriptor, 0, *n);
    slot->sent = true;
  }
  return Ok();
}

void CollabSession::ResendAll() {
  impl_->sent_version = 0;
  for (Impl::OwnRoom& r : impl_->own) r.sent = false;
}

Status CollabSession::Receive(CollabMessageType type,
                              std::span<const std::uint8_t> bytes,
                              CollabOutbox& out) {
  Impl& m = *impl_;
  const auto t = static_cast<int>(type);
  auto malformed = [&](Impl::Peer* p, const Error& e) -> Status {
    ++m.stats.malformed;
    if (p != nullptr) ++p->stats.malformed;
    return e;
  };
  auto count = [&](Impl::Peer& p) {
    p.stats.bytes_received[t] += bytes.size();
    ++p.stats.messages_received[t];
  };
  switch (type) {
    case CollabMessageType::kDistilledGraph: {
      auto sender = DistilledSender(bytes);
      if (!sender) return malformed(nullptr, sender.error());
      const std::uint16_t robot = *sender;
      if (robot == 0 || robot == m.config.robot)
        return malformed(nullptr, {Errc::kMalformed, "distilled graph: robot id is 0 or ours"});
      Impl::Peer* p = m.FindOrAddPeer(robot);
      if (p == nullptr) return Error{Errc::kCapacityExceeded, "collab session: peer store full"};
      count(*p);
      auto d = DecodeDistilled(bytes, m.delta, &p->graph);
      if (!d) return malformed(p, d.error());
      if (m.delta.robot != robot)
        return malformed(p, {Errc::kMalformed, "distilled graph: robot id mismatch"});
      if (d->since > p->graph.version) ++p->stats.graph_gaps;  // a delta was lost on the way
      if (auto s = ApplyDistilled(m.delta, p->graph); !s) return s;
      return Ok();
    }
    case CollabMessageType::kRoomDescriptor: {
      auto h = DecodeRoomDescriptor(bytes, m.descriptor_scratch);
      if (!h) return malformed(nullptr, h.error());
      if (h->robot == 0 || h->robot == m.config.robot)
        return malformed(nullptr, {Errc::kMalformed, "room descriptor: robot id is 0 or ours"});
      Impl::Peer* p = m.FindOrAddPeer(h->robot);
      if (p == nullptr) return Error{Errc::kCapacityExceeded, "collab session: peer store full"};
      count(*p);
      if (bytes.size() != m.descriptor_bytes) {
        ++m.stats.descriptors_mismatched;
        return Error{Errc::kUnsupported, "room descriptor: rings x sectors differ from ours"};
      }
      std::size_t slot = m.PeerRoomSlot(*p, h->room);
      if (slot == p->rooms.size() && !p->rooms.try_push_back({h->room, h->version})) {
        ++m.stats.descriptors_refused;
        return Error{Errc::kCapacityExceeded, "collab session: peer descriptor store full"};
      }
      p->rooms[slot].version = h->version;
      std::copy(
          bytes.begin(), bytes.end(),
          p->descriptor_bytes.begin() + static_cast<std::ptrdiff_t>(slot * m.descriptor_bytes));
      ++p->stats.descriptors;
      return Ok();
    }
    case CollabMessageType::kRoomCloudRequest: {
      auto q = DecodeRoomCloudRequest(bytes);
      if (!q) return malformed(nullptr, q.error());
      if (q->to != m.config.robot) return Ok();  // another robot's business
      Impl::Peer* p = m.FindOrAddPeer(q->from);
      if (p == nullptr) return Error{Errc::kCapacityExceeded, "collab session: peer store full"};
      count(*p);
      const Impl::OwnRoom* room = m.FindOwn(q->room);
      if (room == nullptr) {
        ++m.stats.requests_unknown;
        return Error{Errc::kNotFound, "room cloud request: no such room"};
      }
      // The current cloud, whatever version was asked for: the requester holds (or will hold)
      // the descriptor of this version too.
      RoomCloudHeader header{m.config.robot, room->id, room->version, m.config.cloud_encoding,
                             m.config.cloud_step_m};
      if (header.encoding == CloudEncoding::kQuantised8) {
        // 8 bits: the step grows with a large room so that it fits (+-127 steps), up to a
        // quarter of the 0.5 m VGICP voxels; beyond that the room goes at 1 cm in 16 bits.
        float reach = 0;
        for (const Eigen::Vector3f& point : room->cloud)
          reach = std::max(reach, point.cwiseAbs().maxCoeff());
        header.step_m = std::max(header.step_m, reach / 126.0f);
        if (header.step_m > m.config.max_cloud_step_m) {
          ++m.stats.cloud_encoding_fallbacks;
          header.encoding = CloudEncoding::kQuantised16;
          header.step_m = 0.01f;
        }
      }
      auto n = EncodeRoomCloud(header, room->cloud.span(), m.buffer);
      if (!n) {
        ++m.stats.encode_failures;
        return n.error();
      }
      ++m.stats.requests_served;
      m.Send(out, CollabMessageType::kRoomCloud, q->from, *n);
      return Ok();
    }
    case CollabMessageType::kRoomCloud: {
      auto h = DecodeRoomCloud(bytes, m.cloud_scratch);
      if (!h) return malformed(nullptr, h.error());
      if (h->robot == 0 || h->robot == m.config.robot)
        return malformed(nullptr, {Errc::kMalformed, "room cloud: robot id is 0 or ours"});
      Impl::Peer* p = m.FindPeer(h->robot);
      if (p == nullptr) return Error{Errc::kNotFound, "room cloud: from an unknown robot"};
      count(*p);
      bool asked = false;
      for (const Impl::Pending& q : p->pending) asked = asked || q.peer_room == h->room;
      if (!asked) {
        ++m.stats.clouds_unsolicited;
        return Error{Errc::kInvalidArgument, "room cloud: not requested"};
      }
      if (m.cloud_scratch.size() > m.config.max_room_points) {
        ++m.stats.room_clouds_too_large;
        return Error{Errc::kCapacityExceeded, "room cloud: more points than max_room_points"};
      }
      // Into the least recently used cache slot.
      Impl::CachedCloud* slot = &m.cache[0];
      for (Impl::CachedCloud& c : m.cache) {
        if (!c.used) {
          slot = &c;
          break;
        }
        if (c.stamp < slot->stamp) slot = &c;
      }
      if (slot->used) ++m.stats.cache_evictions;
      slot->used = true;
      slot->robot = h->robot;
      slot->room = h->room;
      slot->version = h->version;
      slot->stamp = ++m.cache_clock;
      slot->points.clear();
      for (const Eigen::Vector3f& q : m.cloud_scratch) slot->points.push_back(q);
      // A newer version than asked for: pending proposals of the old one follow it.
      for (Impl::Pending& q : p->pending) {
        if (q.peer_room == h->room) q.peer_version = h->version;
      }
      return Ok();
    }
  }
  return malformed(nullptr, {Errc::kMalformed, "collab session: unknown message type"});
}

bool CollabSession::Impl::MatchPeer(Peer& p, CollabOutbox& out) {
  bool changed = false;
  // 1. Proposals waiting for a room cloud.
  std::size_t kept = 0;
  for (std::size_t i = 0; i < p.pending.size(); ++i) {
    Pending q = p.pending[i];
    const OwnRoom* mine = FindOwn(q.own_room);
    const DistilledRoom* theirs = p.graph.FindRoom(q.peer_room);
    const std::size_t slot = PeerRoomSlot(p, q.peer_room);
    if (mine == nullptr || mine->version != q.own_version || theirs == nullptr ||
        slot == p.rooms.size()) {
      continue;  // stale: a new version is proposed afresh
    }
    if (const CachedCloud* c = FindCached(p.robot, q.peer_room, q.peer_version)) {
      changed = Align(p, q, *mine, *theirs, *c) || changed;
      continue;
    }
    if (calls - q.requested_call >= config.request_retry_calls) {
      // Several of our rooms may wait for the same cloud: one request for all of them.
      bool sent_this_call = false;
      for (std::size_t k = 0; k < kept; ++k) {
        const Pending& o = p.pending[k];
        sent_this_call |= o.peer_room == q.peer_room && o.peer_version == q.peer_version &&
                          o.requested_call == calls;
      }
      if (!sent_this_call) SendRequest(out, p, q);
      q.requested_call = calls;
    }
    p.pending[kept++] = q;
  }
  p.pending.resize_down(kept);

  // 2. New Scan Context proposals.
  const bool anchored = p.merged && p.consistent_count >= config.anchored_matches;
  for (std::size_t j = 0; j < p.rooms.size(); ++j) {
    const PeerRoom& pr = p.rooms[j];
    const DistilledRoom* theirs = p.graph.FindRoom(pr.id);
    if (theirs == nullptr) continue;  // its graph entry has not arrived yet
    bool decoded = false;
    for (std::size_t i = 0; i < own.size(); ++i) {
      const OwnRoom& mine = own[i];
      if (!mine.used) continue;
      const std::uint64_t key = (static_cast<std::uint64_t>(mine.version) << 32) | pr.version;
      std::uint64_t& tried = p.tried[j * own.size() + i];
      if (tried == key) continue;
      tried = key;
      if (mine.room.shape != theirs->shape) continue;
      if (!decoded) {
        const std::span<const std::uint8_t> bytes(&p.descriptor_bytes[j * descriptor_bytes],
                                                  descriptor_bytes);
        if (!DecodeRoomDescriptor(bytes, descriptor_scratch)) break;
        decoded = true;
      }
      const auto sc = ScanContextDistance(mine.descriptor, descriptor_scratch, true);
      if (!sc || sc->distance > config.matcher.sc_threshold) continue;
      ++stats.proposals;
      RoomMatch m;
      m.robot_a = config.robot;
      m.robot_b = p.robot;
      m.room_a = mine.id;
      m.room_b = pr.id;
      m.sc_distance = sc->distance;
      const Eigen::Isometry3d T_ma_ra = RoomFrame(mine.room, floor_z_m);
      const Eigen::Isometry3d T_mb_rb = RoomFrame(*theirs, PeerFloor(p));
      if (anchored) {
        // The candidate must agree with the merged estimate (up to the room's quarter turns),
        // or it is an identical room elsewhere. No cloud crosses the radio.
        ++stats.checked_anchored;
        bool agrees = false;
        for (int turn = 0; turn < 4 && !agrees; ++turn) {
          const Eigen::Isometry3d T = MatchFromRoomFrames(
              T_ma_ra, T_mb_rb, static_cast<double>(sc->yaw_rad) + turn * kQuarterTurn);
          const Eigen::Isometry3d e = p.T_self_peer.inverse() * T;
          if (e.translation().head<2>().norm() < config.anchored_translation_m &&
              Eigen::AngleAxisd(e.linear()).angle() < config.anchored_rotation_rad) {
            m.T_a_b = T;
            agrees = true;
          }
        }
        if (!agrees) {
          ++stats.rejected_anchored;
          continue;
        }
        changed = AddMatch(p, m) || changed;
      } else if (config.mode.fine) {
        Pending q{mine.id,    mine.version, pr.id,
                  pr.version, sc->distance, static_cast<float>(sc->yaw_rad),
                  calls};
        if (const CachedCloud* c = FindCached(p.robot, pr.id, pr.version)) {
          changed = Align(p, q, mine, *theirs, *c) || changed;
          continue;
        }
        bool outstanding = false;
        for (const Pending& o : p.pending) {
          outstanding = outstanding || (o.peer_room == pr.id && o.peer_version == pr.version);
        }
        if (!p.pending.try_push_back(q)) {
          ++stats.pending_refused;
          tried = kUntried;  // proposed again on a later call
          continue;
        }
        if (!outstanding) SendRequest(out, p, q);
      } else {
        m.T_a_b = MatchFromRoomFrames(T_ma_ra, T_mb_rb, static_cast<double>(sc->yaw_rad));
        changed = AddMatch(p, m) || changed;
      }
    }
  }
  return changed;
}

std::size_t CollabSession::Impl::ChooseConsistent(Peer& p, const DistilledGraph& mine) {
  std::uint64_t sets[kMaxHypotheses] = {};
  // Single matches too: they cannot be accepted alone, but their walls can veto a set.
  const std::size_t found = MatchHypotheses(p.matches.span(), config.matcher, 1, sets);
  p.hypotheses = found;
  if (found == 0) return 0;
  std::size_t counts[kMaxHypotheses] = {};
  double agreement_m[kMaxHypotheses] = {};
  for (std::size_t h = 0; h < found; ++h) {
    counts[h] = static_cast<std::size_t>(std::popcount(sets[h]));
    // The hypothesis's transform: its best fine alignment (any member when none is fine).
    const RoomMatch* pick = nullptr;
    for (std::uint32_t i = 0; i < p.matches.size(); ++i) {
      if (!((sets[h] >> i) & 1ull)) continue;
      const RoomMatch& m = p.matches[i];
      if (pick == nullptr || (m.fine_aligned && (!pick->fine_aligned || m.fitness_m2 < pick->fitness_m2)))
        pick = &m;
    }
    agreement_m[h] = config.hypotheses.use_walls
                         ? WallAgreement_m(mine, p.graph, pick->T_a_b, config.hypotheses)
                         : 0.0;
  }
  const int chosen = ChooseHypothesis(std::span(counts, found), std::span(agreement_m, found),
                                      config.matcher.min_consistent, config.hypotheses);
  // Undecided: a set large enough to accept, but a rival as good (a tie, or better walls).
  p.undecided = chosen < 0 && counts[0] >= config.matcher.min_consistent;
  // For the report: the chosen set's (or the first's) wall agreement and the best rival's.
  const std::size_t shown = chosen < 0 ? 0 : static_cast<std::size_t>(chosen);
  p.agreement_m[0] = agreement_m[shown];
  p.agreement_m[1] = 0;
  p.hypothesis_matches[0] = counts[shown];
  p.hypothesis_matches[1] = 0;
  for (std::size_t h = 0; h < found; ++h) {
    if (h == shown || agreement_m[h] < p.agreement_m[1]) continue;
    p.agreement_m[1] = agreement_m[h];
    p.hypothesis_matches[1] = counts[h];
  }
  stats.undecided += p.undecided ? 1u : 0u;
  if (chosen < 0) return 0;
  return HypothesisMembers(sets[chosen],
                           std::span<std::uint32_t>(p.consistent.data(), p.consistent.size()));
}

void CollabSession::Impl::Solve() {
  graph.Clear();
  wall_pairs.clear();
  stats.accepted = stats.rejected_consistency = stats.undecided = 0;
  stats.graph_refused = 0;
  const DistilledGraph& mine = distiller.graph();
  for (Peer& p : peers) {
    if (!p.used) continue;
    p.consistent_count = ChooseConsistent(p, mine);
    stats.accepted += p.consistent_count;
    stats.rejected_consistency += p.matches.size() - p.consistent_count;
    if (p.consistent_count == 0) {
      p.merged = false;
      continue;
    }
    // Start from the previous estimate when it is the same hypothesis: the solve then only
    // refines. A hypothesis that replaced another starts from its own match.
    const Eigen::Isometry3d& first = p.matches[p.consistent[0]].T_a_b;
    const Eigen::Isometry3d e = p.T_self_peer.inverse() * first;
    const bool same = p.merged && e.translation().head<2>().norm() < config.anchored_translation_m &&
                      Eigen::AngleAxisd(e.linear()).angle() < config.anchored_rotation_rad;
    const Eigen::Isometry3d initial = same ? p.T_self_peer : first;
    if (!graph.SetInitial(p.robot, initial)) continue;
    for (std::size_t k = 0; k < p.consistent_count; ++k) {
      const RoomMatch& m = p.matches[p.consistent[k]];
      if (m.fine_aligned) {
        static_cast<void>(graph.AddOriginMeasurement(p.robot, m.T_a_b, config.fine_origin_sigma_m,
                                                     config.fine_origin_sigma_rad));
      }
      const DistilledRoom* ra = mine.FindRoom(m.room_a);
      const DistilledRoom* rb = p.graph.FindRoom(m.room_b);
      if (ra == nullptr || rb == nullptr) continue;
      auto na = graph.AddRoom(config.robot, *ra, floor_z_m);
      auto nb = graph.AddRoom(p.robot, *rb, PeerFloor(p));
      if (na && nb) static_cast<void>(graph.AddRoomRoom(*na, *nb));
      if (!config.mode.walls) continue;
      // Pair the two rooms' walls through the match: same facing and offset after T_a_b.
      for (std::int32_t wa : ra->walls) {
        const DistilledWall* A = wa < 0 ? nullptr : mine.FindWall(static_cast<std::uint32_t>(wa));
        if (A == nullptr) continue;
        for (std::int32_t wb : rb->walls) {
          const DistilledWall* B =
              wb < 0 ? nullptr : p.graph.FindWall(static_cast<std::uint32_t>(wb));
          if (B == nullptr) continue;
          const Eigen::Vector3d n = m.T_a_b.linear() * B->normal;
          const double d = B->d - n.dot(m.T_a_b.translation());
          if (n.dot(A->normal) < std::cos(config.wall_pair_angle_rad) ||
              std::fabs(d - A->d) > config.wall_pair_offset_m) {
            continue;
          }
          auto wa_node = graph.AddWall(config.robot, *A);
          auto wb_node = graph.AddWall(p.robot, *B);
          if (!wa_node || !wb_node) continue;
          static_cast<void>(graph.AddWallWall(*wa_node, *wb_node));
          bool known = false;
          for (const SessionWallPair& q : wall_pairs)
            known = known || (q.own_wall == A->id && q.peer == p.robot && q.peer_wall == B->id);
          if (!known && !wall_pairs.try_push_back({A->id, B->id, p.robot}))
            ++stats.wall_pairs_refused;
        }
      }
    }
  }
  // Everything else each merged robot mapped is attached too (one factor each: it does not move
  // the estimate, but the graph then holds every robot's walls and rooms in this frame).
  auto attach = [&](std::uint16_t robot, const DistilledGraph& g, double floor) {
    for (const DistilledWall& w : g.walls) stats.graph_refused += graph.AddWall(robot, w) ? 0u : 1u;
    for (const DistilledRoom& r : g.rooms)
      stats.graph_refused += graph.AddRoom(robot, r, floor) ? 0u : 1u;
  };
  bool any_merged = false;
  for (Peer& p : peers) {
    if (!p.used || p.consistent_count == 0 || !graph.has_robot(p.robot)) continue;
    attach(p.robot, p.graph, PeerFloor(p));
    any_merged = true;
  }
  if (any_merged) attach(config.robot, mine, floor_z_m);
  ++stats.solves;
  if (!graph.Solve()) ++stats.solve_failures;
  solved_version = distiller.graph().version;
  for (Peer& p : peers) {
    if (!p.used) continue;
    p.solved_version = p.graph.version;
    if (p.consistent_count == 0) continue;
    p.merged = graph.has_robot(p.robot);
    if (p.merged) p.T_self_peer = graph.T_self_robot(p.robot);
  }
}

bool CollabSession::Match(CollabOutbox& out) {
  Impl& m = *impl_;
  ++m.calls;
  bool changed = false;
  bool moved = false;  // a merged map changed since the last solve: its nodes moved
  for (Impl::Peer& p : m.peers) {
    if (!p.used) continue;
    changed = m.MatchPeer(p, out) || changed;
    moved = moved || (p.merged && p.graph.version != p.solved_version);
  }
  moved = moved || (m.stats.solves > 0 && m.distiller.graph().version != m.solved_version);
  if (changed || moved) m.Solve();
  return changed;
}

const DistilledGraph& CollabSession::distilled() const { return impl_->distiller.graph(); }

bool CollabSession::merged(std::uint16_t robot) const {
  if (robot == impl_->config.robot) return true;
  const Impl::Peer* p = impl_->FindPeer(robot);
  return p != nullptr && p->merged;
}

Eigen::Isometry3d CollabSession::T_self_robot(std::uint16_t robot) const {
  const Impl::Peer* p = impl_->FindPeer(robot);
  return p != nullptr && p->merged ? p->T_self_peer : Eigen::Isometry3d::Identity();
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

std::size_t CollabSession::PlanePriors(std::span<PlanePrior> out) const {
  Impl& m = *impl_;
  std::size_t n = 0;
  for (const SessionWallPair& q : m.wall_pairs) {
    if (n == out.size()) break;
    const Impl::Peer* p = m.FindPeer(q.peer);
    if (p == nullptr || !p->merged) continue;
    const DistilledWall* B = p->graph.FindWall(q.peer_wall);
    if (B == nullptr) continue;
    // The peer's wall in this map frame. For level frames WallBasis turns with the yaw, so the
    // covariance keeps its coordinates.
    const Eigen::Isometry3d& T = p->T_self_peer;
    PlanePrior& prior = out[n];
    prior.plane = q.own_wall;
    prior.normal = (T.linear() * B->normal).normalized();
    prior.d = B->d - prior.normal.dot(T.translation());
    const double fm = m.config.feedback_sigma_floor_m, fr = m.config.feedback_sigma_floor_rad;
    prior.covariance = m.config.feedback_inflation * B->covariance;
    prior.covariance.diagonal() += Eigen::Vector3d(fr * fr, fr * fr, fm * fm);
    ++n;
  }
  return n;
}

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
    s.hypotheses = p.hypotheses;
    s.undecided = p.undecided;
    s.agreement_m[0] = p.agreement_m[0];
    s.agreement_m[1] = p.agreement_m[1];
    s.hypothesis_matches[0] = p.hypothesis_matches[0];
    s.hypothesis_matches[1] = p.hypothesis_matches[1];
    return s;
  }
  return {};
}

const CollabSessionStats& CollabSession::stats() const { return impl_->stats; }
const CollabSessionConfig& CollabSession::config() const { return impl_->config; }

}  // namespace msgraphs::core
