// SPDX-License-Identifier: MIT
// The three frames of one encoder-odometry sample (../shared/spec/spot_odometry.dbc):
//   0x120 OdomDeltaPlanar  DeltaX, DeltaY (0.1 mm), DeltaYaw (1e-5 rad), Sequence, Crc8
//   0x121 OdomDeltaSpatial DeltaZ (0.1 mm), DeltaRoll, DeltaPitch (1e-5 rad), Sequence, Crc8
//   0x122 OdomSampleTime   SampleTime (us, wraps at 2^32), Status, Reserved, Sequence, Crc8
// All signals little-endian (Intel); deltas are signed 16-bit. Pure decode and encode.
#pragma once

#include <array>
#include <cstdint>

#include "msgraphs/base/expected.hpp"
#include "msgraphs/drivers/can_odometry/can_frame.hpp"

namespace msgraphs::drivers::can_odometry {

inline constexpr std::uint32_t kPlanarId = 0x120;
inline constexpr std::uint32_t kSpatialId = 0x121;
inline constexpr std::uint32_t kSampleTimeId = 0x122;

inline constexpr double kTranslationUnitM = 1e-4;
inline constexpr double kRotationUnitRad = 1e-5;

inline constexpr std::uint8_t kStatusValid = 0x01;
inline constexpr std::uint8_t kStatusSlipSuspected = 0x02;

enum class OdomFrameKind : std::uint8_t { kPlanar, kSpatial, kSampleTime };

struct OdomFrame {
  OdomFrameKind kind = OdomFrameKind::kPlanar;
  std::uint8_t sequence = 0;
  // kPlanar: a = DeltaX, b = DeltaY, c = DeltaYaw. kSpatial: a = DeltaZ, b = DeltaRoll,
  // c = DeltaPitch. Raw signed counts; scale with the units above.
  std::int16_t a = 0, b = 0, c = 0;
  // kSampleTime only.
  std::uint32_t sample_time_us = 0;
  std::uint8_t status = 0;
};

/// kNotFound: an id this DBC does not define (count and skip). kMalformed: extended or remote
/// frame, or a length other than 8. kChecksum: CRC mismatch.
Expected<OdomFrame> DecodeOdomFrame(const CanFrame& frame);

/// One sample, physical units, as the bridge (or the simulator) sends it.
struct OdomSampleValues {
  std::uint8_t sequence = 0;
  std::uint32_t sample_time_us = 0;
  std::uint8_t status = kStatusValid;
  double dx_m = 0, dy_m = 0, dz_m = 0;
  double droll_rad = 0, dpitch_rad = 0, dyaw_rad = 0;
};

/// The three frames (0x120, 0x121, 0x122 in send order) with CRCs. Values beyond a signal's
/// range saturate (the DBC's ranges: +-3.2767 m, +-0.32767 rad per sample).
std::array<CanFrame, 3> EncodeOdomSample(const OdomSampleValues& sample);

}  // namespace msgraphs::drivers::can_odometry
