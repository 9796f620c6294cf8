// SPDX-License-Identifier: MIT
#include "msgraphs/base/ipv4.hpp"

namespace msgraphs {

Expected<std::uint32_t> ParseIpv4Address(const char* text) {
  if (text == nullptr) return Error{Errc::kInvalidArgument, "ipv4: null address"};
  std::uint32_t address = 0;
  const char* p = text;
  for (int octet = 0; octet < 4; ++octet) {
    if (*p < '0' || *p > '9') return Error{Errc::kInvalidArgument, "ipv4: expected a digit"};
    std::uint32_t v = 0;
    int digits = 0;
    while (*p >= '0' && *p <= '9') {
      v = v * 10 + static_cast<std::uint32_t>(*p - '0');
      if (++digits > 3 || v > 255) return Error{Errc::kInvalidArgument, "ipv4: octet above 255"};
      ++p;
    }
    address = (address << 8) | v;
    if (octet < 3) {
      if (*p != '.') return Error{Errc::kInvalidArgument, "ipv4: expected a dot"};
      ++p;
    }
  }
  if (*p != '\0') return Error{Errc::kInvalidArgument, "ipv4: trailing characters"};
  return address;
}

std::array<char, 16> FormatIpv4Address(std::uint32_t address) {
  std::array<char, 16> text{};
  std::size_t n = 0;
  for (int octet = 3; octet >= 0; --octet) {
    const auto v = static_cast<unsigned>((address >> (8 * octet)) & 0xFFu);
    if (v >= 100) text[n++] = static_cast<char>('0' + v / 100);
    if (v >= 10) text[n++] = static_cast<char>('0' + (v / 10) % 10);
    text[n++] = static_cast<char>('0' + v % 10);
    if (octet > 0) text[n++] = '.';
  }
  text[n] = '\0';
  return text;
}

}  // namespace msgraphs
