// SPDX-License-Identifier: MIT
#include "msgraphs/drivers/velodyne/data_packet_decoder.hpp"

#include <array>
#include <cmath>
#include <numbers>
#include <vector>

namespace msgraphs::drivers::velodyne {

// Azimuth sine/cosine for every 0.01 degree step and per-laser elevation terms, computed once
// in Create so that Decode is table lookups and multiplies only.
struct DataPacketDecoder::Tables {
  std::vector<float> cos_azimuth;
  std::vector<float> sin_azimuth;
  std::array<float, 32> cos_elevation{};
  std::array<float, 32> sin_elevation{};
  std::array<float, 32> z_offset_m{};
};

namespace {

// A block-to-block azimuth step above 3 degrees is not a rotating sensor (1200 RPM VLP-16 moves
// 0.8 degrees per block): it is a glitch or a packet stitched from two rotations. Interpolation
// is then switched off for that block instead of smearing points across the gap.
constexpr std::uint32_t kMaxPlausibleStepCdeg = 300;

std::uint32_t WrapForward(std::uint32_t from, std::uint32_t to) {
  return (to + kAzimuthUnitsPerTurn - from) % kAzimuthUnitsPerTurn;
}

}  // namespace

Status DecoderConfig::Validate() const {
  if (!(min_range_m >= 0.0) || !(max_range_m > min_range_m) || !std::isfinite(max_range_m)) {
    return Error{Errc::kInvalidConfig, "velodyne: need 0 <= min_range_m < max_range_m, finite"};
  }
  return Ok();
}

Expected<DataPacketDecoder> DataPacketDecoder::Create(const DecoderConfig& config) {
  if (Status s = config.Validate(); !s) return s.error();
  auto tables = std::make_shared<Tables>();
  tables->cos_azimuth.resize(kAzimuthUnitsPerTurn);
  tables->sin_azimuth.resize(kAzimuthUnitsPerTurn);
  for (std::uint32_t a = 0; a < kAzimuthUnitsPerTurn; ++a) {
    const double rad = static_cast<double>(a) * (std::numbers::pi / 18000.0);
    tables->cos_azimuth[a] = static_cast<float>(std::cos(rad));
    tables->sin_azimuth[a] = static_cast<float>(std::sin(rad));
  }
  const ModelInfo& info = GetModelInfo(config.model);
  for (int i = 0; i < info.lasers; ++i) {
    const auto k = static_cast<std::size_t>(i);
    tables->cos_elevation[k] = static_cast<float>(std::cos(info.laser[k].elevation_rad));
    tables->sin_elevation[k] = static_cast<float>(std::sin(info.laser[k].elevation_rad));
    tables->z_offset_m[k] =
        config.apply_vertical_offsets ? static_cast<float>(info.laser[k].vertical_offset_m) : 0.0f;
  }
  return DataPacketDecoder(config, std::move(tables));
}

DataPacketDecoder::DataPacketDecoder(const DecoderConfig& config,
                                     std::shared_ptr<const Tables> tables)
    : config_(config), model_(&GetModelInfo(config.model)), tables_(std::move(tables)) {}

Status ValidateDataPacket(std::span<const std::uint8_t> payload) {
  if (payload.size() != kDataPacketBytes) {
    return Error{Errc::kMalformed, "velodyne: data packet is not 1206 bytes"};
  }
  for (int b = 0; b < kBlocksPerPacket; ++b) {
    const std::uint8_t* block = payload.data() + static_cast<std::size_t>(b) * kBlockBytes;
    if (ReadU16Le(block) != kBlockFlag) {
      return Error{Errc::kMalformed, "velodyne: block flag is not FF EE"};
    }
    if (ReadU16Le(block + 2) >= kAzimuthUnitsPerTurn) {
      return Error{Errc::kMalformed, "velodyne: azimuth above 359.99 degrees"};
    }
  }
  const std::uint8_t mode = payload[kReturnModeOffset];
  if (mode != static_cast<std::uint8_t>(ReturnMode::kStrongest) &&
      mode != static_cast<std::uint8_t>(ReturnMode::kLast) &&
      mode != static_cast<std::uint8_t>(ReturnMode::kDual)) {
    return Error{Errc::kMalformed, "velodyne: unknown return mode byte"};
  }
  if (ReadU32Le(payload.data() + kTimestampOffset) >= kMicrosecondsPerHour) {
    return Error{Errc::kMalformed, "velodyne: timestamp beyond one hour"};
  }
  return Ok();
}

Expected<DecodedPacket> DataPacketDecoder::Decode(std::span<const std::uint8_t> payload,
                                                  std::span<VelodynePoint> out) const {
  if (out.size() < kMaxPointsPerPacket) {
    return Error{Errc::kInvalidArgument, "velodyne: output buffer below kMaxPointsPerPacket"};
  }
  if (Status s = ValidateDataPacket(payload); !s) return s.error();

  const std::uint8_t* bytes = payload.data();
  DecodedPacket result;
  result.return_mode = static_cast<ReturnMode>(bytes[kReturnModeOffset]);
  result.product_id = bytes[kProductIdOffset];
  result.device_time_us = ReadU32Le(bytes + kTimestampOffset);
  const bool dual = result.return_mode == ReturnMode::kDual;
  const ModelInfo& info = *model_;
  result.packet_duration_ns = info.PacketDurationNs(result.return_mode);

  // One azimuth per firing (a dual pair shares one firing and must share its azimuth).
  const int firings = dual ? kBlocksPerPacket / 2 : kBlocksPerPacket;
  std::array<std::uint32_t, kBlocksPerPacket> firing_azimuth{};
  for (int f = 0; f < firings; ++f) {
    const int block = dual ? 2 * f : f;
    const std::uint8_t* p = bytes + static_cast<std::size_t>(block) * kBlockBytes;
    firing_azimuth[static_cast<std::size_t>(f)] = ReadU16Le(p + 2);
    if (dual && ReadU16Le(p + kBlockBytes + 2) != ReadU16Le(p + 2)) {
      return Error{Errc::kMalformed, "velodyne: dual-return block pair with different azimuths"};
    }
  }
  std::array<std::uint32_t, kBlocksPerPacket> step{};
  for (int f = 0; f + 1 < firings; ++f) {
    const auto k = static_cast<std::size_t>(f);
    const std::uint32_t d = WrapForward(firing_azimuth[k], firing_azimuth[k + 1]);
    step[k] = d <= kMaxPlausibleStepCdeg ? d : 0;
  }
  // The last firing has no successor inside the packet: reuse the previous step.
  step[static_cast<std::size_t>(firings - 1)] = firings > 1 ? step[static_cast<std::size_t>(firings - 2)] : 0;
  result.first_azimuth_cdeg = static_cast<std::uint16_t>(firing_azimuth[0]);
  result.last_azimuth_cdeg =
      static_cast<std::uint16_t>(firing_azimuth[static_cast<std::size_t>(firings - 1)]);
  result.end_azimuth_cdeg = static_cast<std::uint16_t>(
      (firing_azimuth[static_cast<std::size_t>(firings - 1)] + step[static_cast<std::size_t>(firings - 1)]) %
      kAzimuthUnitsPerTurn);

  const Tables& t = *tables_;
  const std::uint32_t block_ns = info.block_duration_ns;
  const auto min_units = static_cast<std::uint32_t>(std::ceil(config_.min_range_m / kDistanceUnitM));
  const double max_units_d = std::floor(config_.max_range_m / kDistanceUnitM);
  const auto max_units = static_cast<std::uint32_t>(max_units_d > 65535.0 ? 65535.0 : max_units_d);
  const ReturnTag single_tag =
      result.return_mode == ReturnMode::kLast ? ReturnTag::kLast : ReturnTag::kStrongest;

  std::size_t n = 0;
  for (int b = 0; b < kBlocksPerPacket; ++b) {
    const int f = dual ? b / 2 : b;
    const auto fk = static_cast<std::size_t>(f);
    const ReturnTag tag = dual ? (b % 2 == 0 ? ReturnTag::kDualLast : ReturnTag::kDualStrongest)
                               : single_tag;
    const std::uint8_t* block = bytes + static_cast<std::size_t>(b) * kBlockBytes;
    const std::uint8_t* paired_last = dual && b % 2 == 1 ? block - kBlockBytes : nullptr;
    for (int c = 0; c < kChannelsPerBlock; ++c) {
      const std::uint8_t* rec = block + 4 + static_cast<std::size_t>(c) * kChannelBytes;
      const std::uint16_t distance = ReadU16Le(rec);
      if (distance == 0) {
        ++result.no_return;
        continue;
      }
      if (distance < min_units || distance > max_units) {
        ++result.out_of_range;
        continue;
      }
      if (paired_last != nullptr && config_.drop_duplicate_dual_returns) {
        const std::uint8_t* last = paired_last + 4 + static_cast<std::size_t>(c) * kChannelBytes;
        if (ReadU16Le(last) == distance && last[2] == rec[2]) {
          ++result.dual_duplicates;
          continue;
        }
      }
      const std::uint32_t time_ns = info.ChannelTimeNs(f, c);
      const std::uint32_t in_block_ns = time_ns - static_cast<std::uint32_t>(f) * block_ns;
      const std::uint32_t azimuth =
          (firing_azimuth[fk] + (step[fk] * in_block_ns + block_ns / 2) / block_ns) %
          kAzimuthUnitsPerTurn;
      const int laser = info.LaserOf(c);
      const auto lk = static_cast<std::size_t>(laser);
      const float range_m = static_cast<float>(distance) * static_cast<float>(kDistanceUnitM);
      const float xy_m = range_m * t.cos_elevation[lk];

      VelodynePoint& point = out[n++];
      point.x_m = xy_m * t.cos_azimuth[azimuth];
      point.y_m = -xy_m * t.sin_azimuth[azimuth];
      point.z_m = range_m * t.sin_elevation[lk] + t.z_offset_m[lk];
      point.range_m = range_m;
      point.time_offset_ns = time_ns;
      point.azimuth_cdeg = static_cast<std::uint16_t>(azimuth);
      point.intensity = rec[2];
      point.laser_id = static_cast<std::uint8_t>(laser);
      point.ring = info.laser[lk].ring;
      point.return_tag = tag;
    }
  }
  result.points = static_cast<std::uint16_t>(n);
  return result;
}

}  // namespace msgraphs::drivers::velodyne
