// SPDX-License-Identifier: MIT
#include "msgraphs/runtime/link/link_settings.hpp"

namespace msgraphs::runtime::link {

Status LinkSettings::Validate() const {
  if (Status s = link::Validate(dds); !s) return s;
  if (graph_history < 1 || graph_history > 4096)
    return Error{Errc::kInvalidConfig, "graph history must be 1..4096"};
  if (reader_depth < 16 || reader_depth > 65536)
    return Error{Errc::kInvalidConfig, "reader depth must be 16..65536"};
  if (max_bytes_per_s != 0 && max_bytes_per_s < 10000)
    return Error{Errc::kInvalidConfig, "radio budget below 10 kB/s cannot carry a room cloud"};
  for (int t = 0; t < core::kCollabMessageTypes; ++t) {
    if (max_payload_bytes[static_cast<std::size_t>(t)] < 16 ||
        max_payload_bytes[static_cast<std::size_t>(t)] >
            kMaxPayloadBytes[static_cast<std::size_t>(t)])
      return Error{Errc::kInvalidConfig, "max payload bytes outside what the IDL admits"};
  }
  return Ok();
}

// A DomainParticipantListener is also a DataReaderListener: one object serves both.

}  // namespace msgraphs::runtime::link
