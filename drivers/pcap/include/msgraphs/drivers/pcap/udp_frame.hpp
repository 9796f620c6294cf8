// SPDX-License-Identifier: MIT
// Ethernet (optionally 802.1Q-tagged) / Linux-cooked / raw IPv4 + UDP framing: parsing captured
// frames down to the UDP payload, and building frames for the pcap writer.
#pragma once

#include <cstdint>
#include <span>

#include "msgraphs/base/expected.hpp"
#include "msgraphs/base/ipv4.hpp"
#include "msgraphs/drivers/pcap/pcap_format.hpp"

namespace msgraphs::drivers::pcap {

using msgraphs::Ipv4Endpoint;

struct UdpDatagram {
  Ipv4Endpoint source;
  Ipv4Endpoint destination;
  std::span<const std::uint8_t> payload;  ///< points into the frame
  bool payload_truncated = false;  ///< the capture cut the datagram short (snaplen)
};

/// Frame bytes to a UDP datagram. kUnsupported for traffic that is valid but not IPv4/UDP
/// (ARP, IPv6, TCP, IP fragments after the first): callers skip and count it. kMalformed for
/// headers that contradict themselves (bad IHL, lengths beyond the frame).
Expected<UdpDatagram> ParseUdpFrame(std::uint32_t link_type, std::span<const std::uint8_t> frame);

inline constexpr std::size_t kEthernetIpv4UdpHeaderBytes = 14 + 20 + 8;

/// Writes Ethernet + IPv4 (with header checksum) + UDP headers and the payload into `out`.
/// Returns the frame length; kCapacityExceeded if `out` is too small or the payload exceeds
/// what one IPv4 datagram carries.
Expected<std::size_t> BuildUdpFrame(const Ipv4Endpoint& source, const Ipv4Endpoint& destination,
                                    std::span<const std::uint8_t> payload,
                                    std::span<std::uint8_t> out);

}  // namespace msgraphs::drivers::pcap
