// SPDX-License-Identifier: MIT
// Room matching (paper section VI-B): Scan Context proposals between this robot's rooms and a
// peer's, room cloud requests and fine alignment, and checks against a merged estimate. The
// matches are candidates and evidence for the merge decision (collab_merge.cpp), and measure a
// merged origin directly (collab_solve.cpp).
#include <algorithm>

#include "collab_session_impl.hpp"
#include "msgraphs/core/collab/distilled_codec.hpp"

namespace msgraphs::core {

void CollabSession::Impl::SendRequest(CollabOutbox& out, const Peer& p, const Pending& q) {
  auto n = EncodeRoomCloudRequest({config.robot, p.robot, q.peer_room, q.peer_version}, buffer);
  if (!n) {
    ++stats.encode_failures;
    return;
  }
  ++stats.requests_sent;
  Send(out, CollabMessageType::kRoomCloudRequest, p.robot, *n);
}

bool CollabSession::Impl::AddMatch(Peer& p, const RoomMatch& m) {
  if (!p.matches.try_push_back(m)) {
    ++stats.matches_refused;
    return false;
  }
  return true;
}

// The pending proposal's clouds are both here: align them.
bool CollabSession::Impl::Align(Peer& p, const Pending& q, const OwnRoom& mine, const DistilledRoom& theirs,
                                const CachedCloud& cloud) {
  RoomMatch m;
  m.robot_a = config.robot;
  m.robot_b = p.robot;
  m.room_a = q.own_room;
  m.room_b = q.peer_room;
  m.sc_distance = q.sc_distance;
  const Eigen::Isometry3d T_ma_ra = RoomFrame(mine.at_build, floor_z_m);
  const Eigen::Isometry3d T_mb_rb = RoomFrame(theirs, PeerFloor(p));
  if (!matcher.FineAlign(mine.cloud.span(), T_ma_ra, cloud.points.span(), T_mb_rb, static_cast<double>(q.yaw_rad), m)) {
    ++stats.rejected_fine;
    return false;
  }
  return AddMatch(p, m);
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


}  // namespace msgraphs::core
