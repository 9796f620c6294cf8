// SPDX-License-Identifier: MIT
// How a node joins the DDS network. Kept free of Fast DDS types so that configuration and
// tests need not include Fast DDS headers.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "msgraphs/base/expected.hpp"

namespace msgraphs::runtime::link {

struct DdsSettings {
  /// DDS domain; robots of one fleet share it. Tests pick their own to stay apart.
  std::uint32_t domain_id = 0;
  /// Only 127.0.0.1 (UDPv4 whitelist, no SHM, no data-sharing): nothing leaves the machine.
  /// Tests and the local demo use this; robots on a radio turn it off.
  bool loopback_only = false;
  /// Unicast discovery peers ("10.0.0.2"), for radios that drop multicast.
  std::vector<std::string> initial_peers;
};

/// Rejects settings Fast DDS would refuse or misread (domain id > 232 breaks the RTPS port
/// mapping; peers must be dotted IPv4 addresses).
Status Validate(const DdsSettings& settings);

}  // namespace msgraphs::runtime::link
