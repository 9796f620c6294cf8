// SPDX-License-Identifier: MIT
// Velodyne UDP payload layout (VLP-16 and HDL-32E). Byte offsets and codes from the sensor
// manuals as summarised in ../shared/reference/formats-and-references.md section 2. All
// multi-byte fields are little-endian; readers below never assume host order or alignment.
#pragma once

#include <cstddef>
#include <cstdint>

#include "msgraphs/base/byte_order.hpp"

namespace msgraphs::drivers::velodyne {

inline constexpr std::size_t kDataPacketBytes = 1206;
inline constexpr std::size_t kPositionPacketBytes = 512;
inline constexpr std::uint16_t kDefaultDataPort = 2368;
inline constexpr std::uint16_t kDefaultPositionPort = 8308;

inline constexpr int kBlocksPerPacket = 12;
inline constexpr std::size_t kBlockBytes = 100;
inline constexpr int kChannelsPerBlock = 32;
inline constexpr std::size_t kChannelBytes = 3;
/// Wire bytes FF EE read as a little-endian uint16 (upper bank; the only one on VLP-16/HDL-32E).
inline constexpr std::uint16_t kBlockFlag = 0xEEFF;
inline constexpr std::uint16_t kAzimuthUnitsPerTurn = 36000;  ///< 0.01 degree units
inline constexpr double kDistanceUnitM = 0.002;               ///< 2 mm per count
inline constexpr std::uint32_t kMicrosecondsPerHour = 3'600'000'000u;

inline constexpr std::size_t kTimestampOffset = 1200;
inline constexpr std::size_t kReturnModeOffset = 1204;
inline constexpr std::size_t kProductIdOffset = 1205;

/// Upper bound of points one data packet can produce (12 blocks x 32 channels), whatever the
/// model or return mode: the size for a caller's per-packet output buffer.
inline constexpr std::size_t kMaxPointsPerPacket =
    static_cast<std::size_t>(kBlocksPerPacket) * kChannelsPerBlock;

enum class ReturnMode : std::uint8_t { kStrongest = 0x37, kLast = 0x38, kDual = 0x39 };

/// Byte 1205. Informational only: early VLP-16 firmware reports 0x21 (the HDL-32E id), so the
/// model is configured or detected from timing, never taken from this byte alone.
enum class ProductId : std::uint8_t {
  kHdl32e = 0x21,
  kVlp16 = 0x22,
  kVlp32ab = 0x23,
  kPuckHiRes = 0x24,
  kVlp32c = 0x28,
  kVelarray = 0x31,
  kVls128 = 0xA1,
};

// The format's fields are little-endian; the readers and writers are base's.
using msgraphs::ReadU16Le;
using msgraphs::ReadU32Le;
using msgraphs::WriteU16Le;
using msgraphs::WriteU32Le;

}  // namespace msgraphs::drivers::velodyne
