// SPDX-License-Identifier: MIT
// CollabSession::ExportReceived: what the session holds of its peers, as the messages that
// would rebuild it (the runtime checkpoint's snapshot of the session).
//
// Why messages rather than a serialiser of the session: Receive already checks and files every
// part of a peer's state that arrives by message, and the rest (matches, merges, the
// collaborative graph) is derived from it by Match. Writing the received state back as
// messages keeps one decoder for the link, the journal and the snapshot, and a restarted session
// decides its merges again from the evidence, exactly as after a journal replay.
#include "collab_session_impl.hpp"
#include "msgraphs/core/collab/distilled_codec.hpp"
#include "msgraphs/core/collab/free_space_codec.hpp"

namespace msgraphs::core {

CollabExportStats CollabSession::ExportReceived(CollabOutbox& out) {
  Impl& m = *impl_;
  CollabExportStats stats;
  const auto send = [&](CollabMessageType type, std::span<const std::uint8_t> bytes) {
    out.Send(type, 0, bytes);
    ++stats.messages;
    stats.bytes += bytes.size();
  };
  for (const Impl::Peer& p : m.peers) {
    if (!p.used) continue;
    // The peer's graph whole (since 0): a later delta from the peer applies on top of it as it
    // did on the copy this one was made of.
    if (p.graph.robot == p.robot && p.graph.version > 0) {
      auto n = EncodeDistilled(p.graph, 0, m.buffer);
      if (n) {
        send(CollabMessageType::kDistilledGraph, std::span(m.buffer).first(*n));
      } else {
        ++stats.failed;
      }
    }
    // Each descriptor as it arrived (filed verbatim), in its slot's order.
    for (std::size_t slot = 0; slot < p.rooms.size(); ++slot)
      send(CollabMessageType::kRoomDescriptor,
           std::span(p.descriptor_bytes).subspan(slot * m.descriptor_bytes, m.descriptor_bytes));
    if (p.has_free) {
      auto n = EncodeFreeSpace({p.robot, p.free_version}, p.free, m.buffer);
      if (n) {
        send(CollabMessageType::kFreeSpace, std::span(m.buffer).first(*n));
      } else {
        ++stats.failed;
      }
    }
  }
  return stats;
}

}  // namespace msgraphs::core
