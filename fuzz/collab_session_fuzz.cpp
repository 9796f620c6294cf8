// SPDX-License-Identifier: MIT
// libFuzzer target: a robot's CollabSession receiving arbitrary messages from the link, as a
// hostile or broken peer could send them. The first byte picks the message type; the rest is
// the body, sealed with the correct CRC-32 so that the decoders and the session's own checks
// past the checksum run. Every 16th input the session also matches (which must cope with
// whatever state the messages left). Invariants: no crash, and the session's stores stay
// within their capacities.
#include <cstdint>
#include <cstdlib>
#include <vector>

#include "msgraphs/core/collab/collab_session.hpp"
#include "sealed_message.hpp"

using namespace msgraphs;
using namespace msgraphs::core;

namespace {

struct NullOutbox final : CollabOutbox {
  std::size_t sent = 0;
  void Send(CollabMessageType, std::uint16_t, std::span<const std::uint8_t> bytes) override {
    sent += bytes.size();
  }
};

CollabSession& Session() {
  static CollabSession session;
  static bool init = false;
  if (!init) {
    CollabSessionConfig config;
    config.robot = 1;
    config.max_peers = 4;
    config.max_peer_rooms = 16;
    config.max_rooms = 8;
    config.distiller.max_walls = 64;
    config.distiller.max_rooms = 16;
    if (!session.Init(config, SGraphConfig{}, -0.5)) std::abort();
    init = true;
  }
  return session;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const std::vector<std::uint8_t> message = SealedMessage(std::span(data + 1, size - 1));
  CollabSession& session = Session();
  NullOutbox out;
  static_cast<void>(
      session.Receive(static_cast<CollabMessageType>(data[0] % kCollabMessageTypes), message, out));
  static std::uint64_t inputs = 0;
  if (++inputs % 16 == 0) static_cast<void>(session.Match(out));
  if (session.peers() > session.config().max_peers) std::abort();
  for (std::size_t i = 0; i < session.peers(); ++i) {
    const CollabPeerStats s = session.peer_stats(i);
    if (s.walls > 64 || s.rooms > 16 || s.descriptors > 16 || s.robot == 1 || s.robot == 0)
      std::abort();
  }
  return 0;
}
