// SPDX-License-Identifier: MIT
#include "msgraphs/drivers/can_odometry/odometry_frames.hpp"

#include <cmath>

#include "msgraphs/base/byte_order.hpp"
#include "msgraphs/drivers/can_odometry/crc8.hpp"

namespace msgraphs::drivers::can_odometry {
namespace {

std::int16_t I16(const std::uint8_t* p) { return static_cast<std::int16_t>(ReadU16Le(p)); }
void PutI16(std::uint8_t* p, std::int16_t v) { WriteU16Le(p, static_cast<std::uint16_t>(v)); }
std::int16_t Quantise(double value, double unit) {
  double counts = std::round(value / unit);
  if (!(counts >= -32768.0)) counts = -32768.0;  // also catches NaN
  if (counts > 32767.0) counts = 32767.0;
  return static_cast<std::int16_t>(counts);
}
CanFrame Sealed(std::uint32_t id, std::array<std::uint8_t, 8> data) {
  CanFrame f;
  f.id = id;
  f.length = 8;
  data[7] = Crc8SaeJ1850({data.data(), 7});
  f.data = data;
  return f;
}

}  // namespace

Expected<OdomFrame> DecodeOdomFrame(const CanFrame& frame) {
  if (frame.error) return Error{Errc::kMalformed, "can: error frame"};
  if (frame.extended || frame.remote) {
    return Error{Errc::kNotFound, "can: extended or remote frame is not odometry"};
  }
  if (frame.id != kPlanarId && frame.id != kSpatialId && frame.id != kSampleTimeId) {
    return Error{Errc::kNotFound, "can: id not in the odometry DBC"};
  }
  if (frame.length != 8) return Error{Errc::kMalformed, "can: odometry frame length is not 8"};
  const std::uint8_t* d = frame.data.data();
  if (Crc8SaeJ1850({d, 7}) != d[7]) return Error{Errc::kChecksum, "can: odometry CRC-8 mismatch"};
  OdomFrame out;
  out.sequence = d[6];
  if (frame.id == kSampleTimeId) {
    out.kind = OdomFrameKind::kSampleTime;
    out.sample_time_us = ReadU32Le(d);
    out.status = d[4];
    return out;
  }
  out.kind = frame.id == kPlanarId ? OdomFrameKind::kPlanar : OdomFrameKind::kSpatial;
  out.a = I16(d);
  out.b = I16(d + 2);
  out.c = I16(d + 4);
  return out;
}

std::array<CanFrame, 3> EncodeOdomSample(const OdomSampleValues& s) {
  std::array<std::uint8_t, 8> planar{};
  PutI16(planar.data(), Quantise(s.dx_m, kTranslationUnitM));
  PutI16(planar.data() + 2, Quantise(s.dy_m, kTranslationUnitM));
  PutI16(planar.data() + 4, Quantise(s.dyaw_rad, kRotationUnitRad));
  planar[6] = s.sequence;
  std::array<std::uint8_t, 8> spatial{};
  PutI16(spatial.data(), Quantise(s.dz_m, kTranslationUnitM));
  PutI16(spatial.data() + 2, Quantise(s.droll_rad, kRotationUnitRad));
  PutI16(spatial.data() + 4, Quantise(s.dpitch_rad, kRotationUnitRad));
  spatial[6] = s.sequence;
  std::array<std::uint8_t, 8> timing{};
  WriteU32Le(timing.data(), s.sample_time_us);
  timing[4] = s.status;
  timing[5] = 0;
  timing[6] = s.sequence;
  return {Sealed(kPlanarId, planar), Sealed(kSpatialId, spatial), Sealed(kSampleTimeId, timing)};
}

}  // namespace msgraphs::drivers::can_odometry
