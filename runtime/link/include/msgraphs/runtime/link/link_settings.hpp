// SPDX-License-Identifier: MIT
// The fleet link's settings (configuration, validation), apart from the link itself so that
// configuration code needs neither Fast DDS nor its generated types.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "msgraphs/base/expected.hpp"
#include "msgraphs/core/collab/collab_session.hpp"
#include "msgraphs/runtime/link/dds_settings.hpp"

namespace msgraphs::runtime::link {

/// The largest payloads the IDL admits (CollabMessages.idl), by core::CollabMessageType.
inline constexpr std::array<std::size_t, core::kCollabMessageTypes> kMaxPayloadBytes = {
    262144, 8192, 64, 1048576, 1048576, 64, 65536};

struct LinkSettings {
  DdsSettings dds;
  /// Radio budget of this robot (all topics); 0: no cap.
  std::uint32_t max_bytes_per_s = 0;
  /// Distilled deltas a writer keeps for late joiners.
  std::uint32_t graph_history = 64;
  /// Samples per topic a reader holds for the node before back-pressure.
  std::uint32_t reader_depth = 256;
  /// Payloads above this are refused (per type, at most kMaxPayloadBytes).
  std::array<std::size_t, core::kCollabMessageTypes> max_payload_bytes = kMaxPayloadBytes;
  Status Validate() const;
};

}  // namespace msgraphs::runtime::link
