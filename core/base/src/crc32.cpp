// SPDX-License-Identifier: MIT
#include "msgraphs/base/crc32.hpp"

#include <array>

namespace msgraphs {
namespace {

constexpr std::array<std::uint32_t, 256> MakeTable() {
  std::array<std::uint32_t, 256> table{};
  for (std::uint32_t i = 0; i < 256; ++i) {
    std::uint32_t c = i;
    for (int k = 0; k < 8; ++k) c = (c & 1u) != 0 ? 0xEDB88320u ^ (c >> 1) : c >> 1;
    table[i] = c;
  }
  return table;
}

constexpr std::array<std::uint32_t, 256> kTable = MakeTable();

}  // namespace

std::uint32_t Crc32(std::span<const std::uint8_t> bytes) noexcept { return Crc32Continue(0, bytes); }

std::uint32_t Crc32Continue(std::uint32_t crc_of_before, std::span<const std::uint8_t> bytes) noexcept {
  std::uint32_t c = crc_of_before ^ 0xFFFFFFFFu;
  for (std::uint8_t b : bytes) c = kTable[(c ^ b) & 0xFFu] ^ (c >> 8);
  return c ^ 0xFFFFFFFFu;
}

}  // namespace msgraphs
