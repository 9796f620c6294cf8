// SPDX-License-Identifier: MIT
#pragma once

#include <cstdint>
#include <span>

namespace msgraphs::drivers::can_odometry {

/// CRC-8/SAE-J1850 as the odometry DBC specifies it (../shared/spec/spot_odometry.dbc):
/// polynomial 0x1D, init 0xFF, xorout 0xFF, no reflection. Check value for "123456789": 0x4B.
/// Table-driven, no allocation.
std::uint8_t Crc8SaeJ1850(std::span<const std::uint8_t> bytes) noexcept;

}  // namespace msgraphs::drivers::can_odometry
