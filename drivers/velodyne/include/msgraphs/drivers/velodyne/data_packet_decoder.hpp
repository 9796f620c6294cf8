// SPDX-License-Identifier: MIT
// Pure decoder of 1206-byte Velodyne data packets into points. No syscalls, no allocation after
// Create(): points go into a caller-provided buffer of kMaxPointsPerPacket entries.
#pragma once

#include <cstdint>
#include <memory>
#include <span>

#include "msgraphs/base/expected.hpp"
#include "msgraphs/drivers/velodyne/packet_format.hpp"
#include "msgraphs/drivers/velodyne/point.hpp"
#include "msgraphs/drivers/velodyne/sensor_model.hpp"

namespace msgraphs::drivers::velodyne {

struct DecoderConfig {
  SensorModel model = SensorModel::kVlp16;
  /// Returns closer than this are dropped (the sensor reports self-hits and noise below ~0.4 m).
  /// Zero-distance channel records mean "no return" and are always dropped and counted.
  double min_range_m = 0.0;
  double max_range_m = 131.07;  ///< 65535 x 2 mm: every representable distance
  /// Apply the manual's per-laser vertical offsets (VLP-16; zero on HDL-32E).
  bool apply_vertical_offsets = true;
  /// In dual mode, when the strongest block repeats the last block's distance for a laser (the
  /// sensor saw a single return), drop the copy so it is not counted twice.
  bool drop_duplicate_dual_returns = true;

  Status Validate() const;
};

struct DecodedPacket {
  std::uint32_t device_time_us = 0;  ///< microseconds past the hour at the first firing
  ReturnMode return_mode = ReturnMode::kStrongest;
  std::uint8_t product_id = 0;
  std::uint16_t first_azimuth_cdeg = 0;
  std::uint16_t last_azimuth_cdeg = 0;   ///< the last firing's block azimuth
  /// Where the rotation will be when the next firing starts (last azimuth + its step): the
  /// end of the azimuth range this packet covers.
  std::uint16_t end_azimuth_cdeg = 0;
  std::uint32_t packet_duration_ns = 0;  ///< first firing to end of last firing
  std::uint16_t points = 0;              ///< written to the output buffer
  std::uint16_t no_return = 0;           ///< zero-distance channel records
  std::uint16_t out_of_range = 0;        ///< outside [min_range_m, max_range_m]
  std::uint16_t dual_duplicates = 0;     ///< dual-mode copies dropped
};

class DataPacketDecoder {
 public:
  static Expected<DataPacketDecoder> Create(const DecoderConfig& config);

  /// Decodes one payload. Errors (kMalformed with a reason) leave `out` unspecified and write
  /// nothing to the caller's counters; the caller counts them. `out` must hold at least
  /// kMaxPointsPerPacket points (kInvalidArgument otherwise).
  Expected<DecodedPacket> Decode(std::span<const std::uint8_t> payload,
                                 std::span<VelodynePoint> out) const;

  const DecoderConfig& config() const { return config_; }
  const ModelInfo& model() const { return *model_; }

 private:
  struct Tables;
  DataPacketDecoder(const DecoderConfig& config, std::shared_ptr<const Tables> tables);

  DecoderConfig config_;
  const ModelInfo* model_;
  std::shared_ptr<const Tables> tables_;  // shared: copies of a decoder share the trig tables
};

/// Checks the fixed parts of a data packet (size, block flags, azimuth range, return mode)
/// without decoding points. Useful to classify traffic on a port.
Status ValidateDataPacket(std::span<const std::uint8_t> payload);

}  // namespace msgraphs::drivers::velodyne
