// SPDX-License-Identifier: MIT
#include "msgraphs/runtime/link/dds_settings.hpp"

#include <arpa/inet.h>

#include <cstdlib>

namespace msgraphs::runtime::link {

namespace {

bool IsIpv4(const std::string& text) {
  in_addr addr{};
  return inet_pton(AF_INET, text.c_str(), &addr) == 1;
}

}  // namespace

bool ParseIpv4Endpoint(const std::string& text, std::string& address, std::uint16_t& port) {
  const std::size_t colon = text.rfind(':');
  if (colon == std::string::npos) return false;
  address = text.substr(0, colon);
  const std::string digits = text.substr(colon + 1);
  if (digits.empty() || digits.size() > 5 ||
      digits.find_first_not_of("0123456789") != std::string::npos)
    return false;
  const long value = std::strtol(digits.c_str(), nullptr, 10);
  if (value < 1 || value > 65535 || !IsIpv4(address)) return false;
  port = static_cast<std::uint16_t>(value);
  return true;
}

Status Validate(const DdsSettings& settings) {
  // RTPS well-known ports are 7400 + 250 * domain + ...; above 232 they leave the port range.
  if (settings.domain_id > 232) return Error{Errc::kInvalidConfig, "DDS domain id must be 0..232"};
  for (const std::string& peer : settings.initial_peers) {
    if (!IsIpv4(peer))
      return Error{Errc::kInvalidConfig, "initial peer is not a dotted IPv4 address"};
  }
  for (const std::string& address : settings.interfaces) {
    if (!IsIpv4(address))
      return Error{Errc::kInvalidConfig, "interface is not a dotted IPv4 address"};
  }
  if (settings.discovery == Discovery::kUnicast && settings.initial_peers.empty() &&
      !settings.loopback_only) {
    return Error{Errc::kInvalidConfig, "unicast discovery needs at least one initial peer"};
  }
  if (settings.discovery == Discovery::kServer) {
    std::string address;
    std::uint16_t port = 0;
    if (!ParseIpv4Endpoint(settings.discovery_server, address, port))
      return Error{Errc::kInvalidConfig, "discovery server must be IPv4:port"};
    if (settings.discovery_server_id > 255)
      return Error{Errc::kInvalidConfig, "discovery server id must be 0..255"};
  }
  if (!(settings.lease_duration_s >= 1.0 && settings.lease_duration_s <= 3600.0))
    return Error{Errc::kInvalidConfig, "lease duration must be 1..3600 s"};
  return Ok();
}

}  // namespace msgraphs::runtime::link
