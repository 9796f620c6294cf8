// SPDX-License-Identifier: MIT
// Per-model geometry and firing timing: laser elevations, vertical offsets, ring order and the
// time of every channel record inside a packet.
#pragma once

#include <array>
#include <cstdint>

#include "msgraphs/drivers/velodyne/packet_format.hpp"

namespace msgraphs::drivers::velodyne {

enum class SensorModel : std::uint8_t { kVlp16, kHdl32e };

const char* ToString(SensorModel model) noexcept;

struct LaserInfo {
  double elevation_rad = 0.0;
  /// Added to z (manual convention). The VLP-16 manual (Rev E) lists -11.2..+11.2 mm; the ROS
  /// driver's calibration sets them to zero. We apply the manual's values: they are real
  /// geometry of the sensor and cost nothing (docs/drivers.md).
  double vertical_offset_m = 0.0;
  std::uint8_t ring = 0;  ///< 0 = lowest elevation, increasing upwards
};

struct ModelInfo {
  SensorModel model;
  int lasers;                        ///< 16 or 32
  int firings_per_block;             ///< VLP-16: 2 sequences of 16 lasers; HDL-32E: 1 of 32
  std::uint32_t block_duration_ns;   ///< time between consecutive single-return blocks
  std::array<LaserInfo, 32> laser;   ///< entries [0, lasers) are used

  /// Firing time of channel record `channel` (0..31) of block `block` (0..11) relative to the
  /// packet's first firing, in nanoseconds. In dual-return mode two blocks share one firing, so
  /// the caller passes block / 2.
  std::uint32_t ChannelTimeNs(int block, int channel) const;
  /// Laser id of channel record `channel`.
  int LaserOf(int channel) const { return channel % lasers; }
  /// Time from the packet's first firing to the end of its last firing.
  std::uint32_t PacketDurationNs(ReturnMode mode) const {
    const int firing_blocks = mode == ReturnMode::kDual ? kBlocksPerPacket / 2 : kBlocksPerPacket;
    return block_duration_ns * static_cast<std::uint32_t>(firing_blocks);
  }
};

/// Identifies the model from the device-time spacing of two consecutive data packets, which
/// differs by model (VLP-16 1327 us single / 664 us dual, HDL-32E 553 us / 276 us) where the
/// product-id byte may lie. Returns false when the spacing fits neither (e.g. a lost packet).
bool ModelFromPacketSpacing(std::uint32_t spacing_us, ReturnMode mode, SensorModel& model);

/// Static tables (computed once, thread-safe static initialisation).
const ModelInfo& GetModelInfo(SensorModel model);

// VLP-16 timing (manual): 2.304 us between lasers, 55.296 us per firing sequence (16 lasers
// plus an 18.43 us recharge), two sequences per block.
inline constexpr std::uint32_t kVlp16LaserSpacingNs = 2304;
inline constexpr std::uint32_t kVlp16SequenceNs = 55296;
// HDL-32E: lasers fire in pairs 1.152 us apart; one block of 32 lasers takes 46.08 us.
inline constexpr std::uint32_t kHdl32ePairSpacingNs = 1152;
inline constexpr std::uint32_t kHdl32eBlockNs = 46080;

}  // namespace msgraphs::drivers::velodyne
