// SPDX-License-Identifier: MIT
// IPv4 endpoint value type shared by the pcap format code and the platform sockets.
#pragma once

#include <array>
#include <cstdint>

#include "msgraphs/base/expected.hpp"

namespace msgraphs {

struct Ipv4Endpoint {
  std::uint32_t address = 0;  ///< host byte order, e.g. 0xC0A801C9 for 192.168.1.201
  std::uint16_t port = 0;

  bool operator==(const Ipv4Endpoint&) const = default;
};

inline constexpr std::uint32_t kIpv4Loopback = 0x7F000001;
inline constexpr std::uint32_t kIpv4Any = 0;

/// "192.168.1.201" to host order; kInvalidArgument on anything else (no names, no shorthand).
Expected<std::uint32_t> ParseIpv4Address(const char* text);

/// Dotted-quad text of an address, NUL-terminated.
std::array<char, 16> FormatIpv4Address(std::uint32_t address);

}  // namespace msgraphs
