// SPDX-License-Identifier: MIT
// A classic CAN frame as the decoders see it, independent of where it came from (SocketCAN,
// a candump log, a simulator).
#pragma once

#include <array>
#include <cstdint>
#include <span>

namespace msgraphs::drivers::can_odometry {

struct CanFrame {
  std::uint32_t id = 0;  ///< 11-bit or 29-bit identifier, without flag bits
  bool extended = false;
  bool remote = false;  ///< RTR
  bool error = false;   ///< an error frame (id then holds the CAN_ERR_* class bits)
  std::uint8_t length = 0;  ///< 0..8
  std::array<std::uint8_t, 8> data{};

  std::span<const std::uint8_t> bytes() const { return {data.data(), length}; }
};

}  // namespace msgraphs::drivers::can_odometry
