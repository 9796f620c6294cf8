// SPDX-License-Identifier: MIT
// CollabSession::Receive: a peer's message decoded into the session's stores (every decoder
// checks it; a malformed one is counted and dropped), a room cloud request answered at once, a
// place request queued for the next exchange.
#include <algorithm>

#include "collab_session_impl.hpp"
#include "msgraphs/core/collab/distilled_codec.hpp"
#include "msgraphs/core/collab/free_space_codec.hpp"

namespace msgraphs::core {

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
        ++m.peer_clouds_too_large;
        m.stats.room_clouds_too_large = m.own_clouds_too_large + m.peer_clouds_too_large;
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
    case CollabMessageType::kFreeSpace: {
      auto h = PeekFreeSpaceHeader(bytes);
      if (!h) return malformed(nullptr, h.error());
      if (h->robot == 0 || h->robot == m.config.robot)
        return malformed(nullptr, {Errc::kMalformed, "free space: robot id is 0 or ours"});
      Impl::Peer* p = m.FindOrAddPeer(h->robot);
      if (p == nullptr) return Error{Errc::kCapacityExceeded, "collab session: peer store full"};
      count(*p);
      if (p->has_free && h->version <= p->free_version) return Ok();  // an old one arrived late
      auto d = DecodeFreeSpace(bytes, p->free);
      if (!d) {
        p->has_free = false;  // the decoder may have overwritten it: wait for the next one
        return malformed(p, d.error());
      }
      p->has_free = true;
      p->free_version = d->version;
      return Ok();
    }
    case CollabMessageType::kPlaceRequest:
      return m.ReceivePlaceRequest(bytes);
    case CollabMessageType::kPlaceCloud:
      return m.ReceivePlaceCloud(bytes);
  }
  return malformed(nullptr, {Errc::kMalformed, "collab session: unknown message type"});
}

}  // namespace msgraphs::core
