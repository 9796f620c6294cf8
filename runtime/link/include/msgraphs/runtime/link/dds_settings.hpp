// SPDX-License-Identifier: MIT
// How a node joins the DDS network. Kept free of Fast DDS types so that configuration and
// tests need not include Fast DDS headers.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "msgraphs/base/expected.hpp"

namespace msgraphs::runtime::link {

enum class Discovery : std::uint8_t {
  kMulticast,  ///< RTPS simple discovery: announcements on the multicast group (the default)
  kUnicast,    ///< no multicast at all: announcements only to `initial_peers`
  kServer,     ///< a Discovery Server client: announcements only to `discovery_server`
};

struct DdsSettings {
  /// DDS domain; robots of one fleet share it. Tests pick their own to stay apart.
  std::uint32_t domain_id = 0;
  /// Only 127.0.0.1 (UDPv4 whitelist, no SHM, no data-sharing): nothing leaves the machine.
  /// Tests and the local demo use this; robots on a radio turn it off.
  bool loopback_only = false;
  /// Restrict UDP to these local interface addresses (e.g. the radio's "10.0.0.2"); empty: all.
  std::vector<std::string> interfaces;
  Discovery discovery = Discovery::kMulticast;
  /// Unicast discovery peers ("10.0.0.2"), for radios that drop multicast. With kMulticast they
  /// are asked in addition to the multicast group; with kUnicast they are the only ones.
  std::vector<std::string> initial_peers;
  /// kServer: the server's "IPv4:port" (e.g. "10.0.0.1:11811", as `fastdds discovery -i 0
  /// -l 10.0.0.1 -p 11811` serves) and its id (0..255, the `-i` of that command).
  std::string discovery_server;
  std::uint32_t discovery_server_id = 0;
  /// A peer that stays silent this long is considered gone (DDS lease duration).
  double lease_duration_s = 10.0;
};

/// Rejects settings Fast DDS would refuse or misread (domain id > 232 breaks the RTPS port
/// mapping; peers must be dotted IPv4 addresses; a server needs an address and a port).
Status Validate(const DdsSettings& settings);

/// Splits "10.0.0.1:11811" into its address and port; false when it is not that form.
bool ParseIpv4Endpoint(const std::string& text, std::string& address, std::uint16_t& port);

}  // namespace msgraphs::runtime::link
