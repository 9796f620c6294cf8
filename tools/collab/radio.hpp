// SPDX-License-Identifier: MIT
// msgraphs_collab's in-process radio: messages wait in order until the mission delivers them to
// their addressees (every peer for a broadcast), and every byte is counted per message type and
// link. Queued rather than delivered at once so that no session is re-entered while it sends.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <span>
#include <tuple>
#include <vector>

#include "msgraphs/core/collab/collab_session.hpp"

namespace msgraphs::tools::collab {

/// The session's seven message types (same values as core::CollabMessageType), then the
/// keyframe-level baseline's two.
enum MessageType {
  kGraph,
  kDescriptor,
  kCloudRequest,
  kCloud,
  kFreeSpace,
  kPlaceRequest,
  kPlaceCloud,
  kKeyframeDescriptor,
  kKeyframeCloud,
  kMessageTypes
};
static_assert(kFreeSpace == static_cast<int>(core::CollabMessageType::kFreeSpace) &&
              kPlaceCloud == static_cast<int>(core::CollabMessageType::kPlaceCloud) &&
              kKeyframeDescriptor == core::kCollabMessageTypes);
/// "distilled graph", ... (reports, bytes.csv columns).
const char* MessageTypeName(int type);
/// "distilled_graph", ... (the JSON summary's keys).
const char* MessageTypeKey(int type);

/// Bytes per (type, from, to); robots by 0-based index.
struct Accounting {
  std::map<std::tuple<int, int, int>, std::uint64_t> bytes;
  std::uint64_t malformed = 0;  ///< messages a receiver's decoder refused
  void Add(MessageType type, int from, int to, std::size_t n) { bytes[{type, from, to}] += n; }
  /// Every type (type < 0) or one.
  std::uint64_t Total(int type = -1) const;
  std::uint64_t Link(int from, int to) const;
};

/// What the sessions send through (core::CollabOutbox): queued with the sender's index.
struct Radio final : core::CollabOutbox {
  struct Message {
    core::CollabMessageType type;
    int from;
    std::uint16_t to;  ///< a robot id, 0 for every peer
    std::vector<std::uint8_t> bytes;
  };
  std::vector<Message> queue;
  int sender = 0;  ///< set by the mission before it lets a session send
  void Send(core::CollabMessageType type,
            std::uint16_t to,
            std::span<const std::uint8_t> bytes) override {
    queue.push_back({type, sender, to, {bytes.begin(), bytes.end()}});
  }
};

}  // namespace msgraphs::tools::collab
