// SPDX-License-Identifier: MIT
#include "msgraphs/drivers/can_odometry/crc8.hpp"

#include <array>

namespace msgraphs::drivers::can_odometry {
namespace {

constexpr std::uint8_t kPolynomial = 0x1D;

constexpr std::array<std::uint8_t, 256> MakeTable() {
  std::array<std::uint8_t, 256> table{};
  for (unsigned i = 0; i < 256; ++i) {
    auto crc = static_cast<std::uint8_t>(i);
    for (int bit = 0; bit < 8; ++bit) {
      crc = static_cast<std::uint8_t>((crc & 0x80u) != 0 ? (crc << 1) ^ kPolynomial : crc << 1);
    }
    table[i] = crc;
  }
  return table;
}

constexpr std::array<std::uint8_t, 256> kTable = MakeTable();

}  // namespace

std::uint8_t Crc8SaeJ1850(std::span<const std::uint8_t> bytes) noexcept {
  std::uint8_t crc = 0xFF;
  for (const std::uint8_t b : bytes) crc = kTable[crc ^ b];
  return static_cast<std::uint8_t>(crc ^ 0xFF);
}

}  // namespace msgraphs::drivers::can_odometry
