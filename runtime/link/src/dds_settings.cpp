// SPDX-License-Identifier: MIT
#include "msgraphs/runtime/link/dds_settings.hpp"

#include <arpa/inet.h>

namespace msgraphs::runtime::link {

Status Validate(const DdsSettings& settings) {
  // RTPS well-known ports are 7400 + 250 * domain + ...; above 232 they leave the port range.
  if (settings.domain_id > 232) return Error{Errc::kInvalidConfig, "DDS domain id must be 0..232"};
  for (const std::string& peer : settings.initial_peers) {
    in_addr addr{};
    if (inet_pton(AF_INET, peer.c_str(), &addr) != 1) {
      return Error{Errc::kInvalidConfig, "initial peer is not a dotted IPv4 address"};
    }
  }
  return Ok();
}

}  // namespace msgraphs::runtime::link
