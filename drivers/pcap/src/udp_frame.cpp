// SPDX-License-Identifier: MIT
#include "msgraphs/drivers/pcap/udp_frame.hpp"

#include <cstring>

namespace msgraphs::drivers::pcap {
namespace {

constexpr std::uint16_t kEtherTypeIpv4 = 0x0800;
constexpr std::uint16_t kEtherTypeVlan = 0x8100;
constexpr std::uint16_t kEtherTypeQinQ = 0x88A8;
constexpr std::uint8_t kProtocolUdp = 17;

std::uint16_t Be16(const std::uint8_t* p) { return static_cast<std::uint16_t>((p[0] << 8) | p[1]); }
std::uint32_t Be32(const std::uint8_t* p) {
  return (static_cast<std::uint32_t>(p[0]) << 24) | (static_cast<std::uint32_t>(p[1]) << 16) |
         (static_cast<std::uint32_t>(p[2]) << 8) | p[3];
}
void PutBe16(std::uint8_t* p, std::uint16_t v) {
  p[0] = static_cast<std::uint8_t>(v >> 8);
  p[1] = static_cast<std::uint8_t>(v & 0xFFu);
}
void PutBe32(std::uint8_t* p, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<std::uint8_t>((v >> (24 - 8 * i)) & 0xFFu);
}

Expected<UdpDatagram> ParseIpv4(std::span<const std::uint8_t> ip) {
  if (ip.size() < 20) return Error{Errc::kMalformed, "pcap: IPv4 header cut short"};
  if ((ip[0] >> 4) != 4) return Error{Errc::kUnsupported, "pcap: not IPv4"};
  const std::size_t header_bytes = static_cast<std::size_t>(ip[0] & 0x0F) * 4;
  if (header_bytes < 20 || header_bytes > ip.size()) {
    return Error{Errc::kMalformed, "pcap: bad IPv4 header length"};
  }
  const std::uint16_t total = Be16(ip.data() + 2);
  if (total < header_bytes) return Error{Errc::kMalformed, "pcap: IPv4 total length below header"};
  const std::uint16_t fragment = Be16(ip.data() + 6);
  if ((fragment & 0x1FFFu) != 0 || (fragment & 0x2000u) != 0) {
    return Error{Errc::kUnsupported, "pcap: IPv4 fragment (not reassembled)"};
  }
  if (ip[9] != kProtocolUdp) return Error{Errc::kUnsupported, "pcap: not UDP"};
  // Captured bytes may be fewer than the IP length (snaplen) or more (Ethernet padding).
  const std::size_t ip_available = total < ip.size() ? total : ip.size();
  const std::span<const std::uint8_t> udp = ip.subspan(header_bytes, ip_available - header_bytes);
  if (udp.size() < 8) return Error{Errc::kMalformed, "pcap: UDP header cut short"};
  const std::uint16_t udp_length = Be16(udp.data() + 4);
  if (udp_length < 8) return Error{Errc::kMalformed, "pcap: UDP length below 8"};
  if (static_cast<std::size_t>(udp_length) > static_cast<std::size_t>(total) - header_bytes) {
    return Error{Errc::kMalformed, "pcap: UDP length beyond the IPv4 datagram"};
  }
  UdpDatagram d;
  d.source = {Be32(ip.data() + 12), Be16(udp.data())};
  d.destination = {Be32(ip.data() + 16), Be16(udp.data() + 2)};
  const std::size_t want = static_cast<std::size_t>(udp_length) - 8;
  const std::size_t have = udp.size() - 8;
  d.payload = udp.subspan(8, want < have ? want : have);
  d.payload_truncated = have < want;
  return d;
}

}  // namespace

Expected<UdpDatagram> ParseUdpFrame(std::uint32_t link_type, std::span<const std::uint8_t> frame) {
  switch (static_cast<LinkType>(link_type)) {
    case LinkType::kEthernet: {
      std::size_t offset = 12;
      if (frame.size() < 14) return Error{Errc::kMalformed, "pcap: Ethernet header cut short"};
      std::uint16_t ether_type = Be16(frame.data() + offset);
      // At most two VLAN tags (802.1ad outer, 802.1Q inner).
      for (int tags = 0; tags < 2 && (ether_type == kEtherTypeVlan || ether_type == kEtherTypeQinQ);
           ++tags) {
        offset += 4;
        if (frame.size() < offset + 2) return Error{Errc::kMalformed, "pcap: VLAN tag cut short"};
        ether_type = Be16(frame.data() + offset);
      }
      if (ether_type != kEtherTypeIpv4) return Error{Errc::kUnsupported, "pcap: not IPv4"};
      return ParseIpv4(frame.subspan(offset + 2));
    }
    case LinkType::kLinuxSll: {
      if (frame.size() < 16) return Error{Errc::kMalformed, "pcap: Linux SLL header cut short"};
      if (Be16(frame.data() + 14) != kEtherTypeIpv4) return Error{Errc::kUnsupported, "pcap: not IPv4"};
      return ParseIpv4(frame.subspan(16));
    }
    case LinkType::kRaw:
      return ParseIpv4(frame);
  }
  return Error{Errc::kUnsupported, "pcap: link type is not Ethernet, raw IP or Linux SLL"};
}

Expected<std::size_t> BuildUdpFrame(const Ipv4Endpoint& source, const Ipv4Endpoint& destination,
                                    std::span<const std::uint8_t> payload,
                                    std::span<std::uint8_t> out) {
  const std::size_t total = kEthernetIpv4UdpHeaderBytes + payload.size();
  if (payload.size() > 65535 - 28 || out.size() < total) {
    return Error{Errc::kCapacityExceeded, "pcap: frame does not fit"};
  }
  std::uint8_t* e = out.data();
  // Destination MAC: broadcast, as Velodyne sensors send by default; source: a locally
  // administered address derived from the IP so that different senders stay distinguishable.
  std::memset(e, 0xFF, 6);
  e[6] = 0x02;
  e[7] = 0x00;
  PutBe32(e + 8, source.address);
  PutBe16(e + 12, kEtherTypeIpv4);
  std::uint8_t* ip = e + 14;
  ip[0] = 0x45;
  ip[1] = 0;
  PutBe16(ip + 2, static_cast<std::uint16_t>(20 + 8 + payload.size()));
  PutBe16(ip + 4, 0);       // identification
  PutBe16(ip + 6, 0x4000);  // don't fragment
  ip[8] = 64;               // TTL
  ip[9] = kProtocolUdp;
  PutBe16(ip + 10, 0);
  PutBe32(ip + 12, source.address);
  PutBe32(ip + 16, destination.address);
  std::uint32_t sum = 0;
  for (int i = 0; i < 20; i += 2) sum += Be16(ip + i);
  while (sum >> 16) sum = (sum & 0xFFFFu) + (sum >> 16);
  PutBe16(ip + 10, static_cast<std::uint16_t>(~sum & 0xFFFFu));
  std::uint8_t* udp = ip + 20;
  PutBe16(udp, source.port);
  PutBe16(udp + 2, destination.port);
  PutBe16(udp + 4, static_cast<std::uint16_t>(8 + payload.size()));
  PutBe16(udp + 6, 0);  // checksum optional over IPv4
  if (!payload.empty()) std::memcpy(udp + 8, payload.data(), payload.size());
  return total;
}

}  // namespace msgraphs::drivers::pcap
