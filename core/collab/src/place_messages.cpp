// SPDX-License-Identifier: MIT
#include "msgraphs/core/collab/place_messages.hpp"

#include <cmath>
#include <cstring>

#include "msgraphs/base/byte_order.hpp"
#include "msgraphs/base/crc32.hpp"

namespace msgraphs::core {
namespace {

constexpr std::uint8_t kFormat = 1;
constexpr std::size_t kCloudHeader = 4 + 1 + 2 + 2 + 4 + 4 + 4 + 4 + 4 + 4;  // 33
/// Map coordinates beyond this are no building's (the free-space summary spans 145 m).
constexpr float kMaxCoordinateM = 1.0e5f;

bool MagicIs(std::span<const std::uint8_t> b, const char* m) { return std::memcmp(b.data(), m, 4) == 0; }

Status CheckCrc(std::span<const std::uint8_t> bytes, std::size_t header) {
  if (bytes.size() < header + 4) return Error{Errc::kMalformed, "place message: shorter than its header"};
  const std::size_t body = bytes.size() - 4;
  if (ReadU32Le(&bytes[body]) != Crc32(bytes.first(body))) return Error{Errc::kChecksum, "place message: CRC mismatch"};
  return Ok();
}

bool PlausibleCoordinate(float v) { return std::isfinite(v) && std::fabs(v) <= kMaxCoordinateM; }

}  // namespace

Expected<std::size_t> EncodePlaceRequest(const PlaceRequest& q, std::span<std::uint8_t> out) {
  if (out.size() < kPlaceRequestBytes) return Error{Errc::kCapacityExceeded, "place request: output buffer too small"};
  if (!(q.radius_m > 0 && q.radius_m <= kMaxPlaceRadiusM) || !PlausibleCoordinate(q.centre_m.x()) ||
      !PlausibleCoordinate(q.centre_m.y()))
    return Error{Errc::kInvalidArgument, "place request: radius or centre out of range"};
  std::uint8_t* p = out.data();
  std::memcpy(p, "MSPQ", 4);
  p[4] = kFormat;
  WriteU16Le(p + 5, q.from);
  WriteU16Le(p + 7, q.to);
  WriteU32Le(p + 9, q.place);
  WriteF32Le(p + 13, q.centre_m.x());
  WriteF32Le(p + 17, q.centre_m.y());
  WriteF32Le(p + 21, q.radius_m);
  WriteU32Le(p + 25, 0);  // reserved
  WriteU32Le(p + 29, Crc32(out.first(29)));
  return kPlaceRequestBytes;
}

Expected<PlaceRequest> DecodePlaceRequest(std::span<const std::uint8_t> bytes) {
  if (auto s = CheckCrc(bytes, kPlaceRequestBytes - 4); !s) return s.error();
  if (bytes.size() != kPlaceRequestBytes) return Error{Errc::kMalformed, "place request: wrong length"};
  if (!MagicIs(bytes, "MSPQ")) return Error{Errc::kMalformed, "place request: bad magic"};
  if (bytes[4] != kFormat) return Error{Errc::kUnsupported, "place request: unknown format"};
  PlaceRequest q;
  q.from = ReadU16Le(&bytes[5]);
  q.to = ReadU16Le(&bytes[7]);
  q.place = ReadU32Le(&bytes[9]);
  q.centre_m = {ReadF32Le(&bytes[13]), ReadF32Le(&bytes[17])};
  q.radius_m = ReadF32Le(&bytes[21]);
  if (q.from == 0 || q.to == 0 || q.from == q.to)
    return Error{Errc::kMalformed, "place request: robot ids must be distinct and non-zero"};
  if (!PlausibleCoordinate(q.centre_m.x()) || !PlausibleCoordinate(q.centre_m.y()))
    return Error{Errc::kMalformed, "place request: centre not finite or implausible"};
  if (!(q.radius_m > 0 && q.radius_m <= kMaxPlaceRadiusM))
    return Error{Errc::kMalformed, "place request: radius out of range"};
  return q;
}

float PlaceCloudStep(float radius_m) {
  const float cm = std::ceil(std::max(radius_m, 1.0f) * 100.0f / 127.0f);
  return 0.01f * cm;
}

std::size_t PlaceCloudEncodedSize(std::size_t points) { return kCloudHeader + 3 * points + 4; }

Expected<std::size_t> EncodePlaceCloud(const PlaceCloudHeader& h,
                                       std::span<const Eigen::Vector3f> points,
                                       std::span<std::uint8_t> out) {
  if (!(h.step_m > 0 && h.step_m <= 1.0f)) return Error{Errc::kInvalidArgument, "place cloud: step out of range"};
  const std::size_t size = PlaceCloudEncodedSize(points.size());
  if (size > out.size()) return Error{Errc::kCapacityExceeded, "place cloud: output buffer too small"};
  std::uint8_t* p = out.data();
  std::memcpy(p, "MSPC", 4);
  p[4] = kFormat;
  WriteU16Le(p + 5, h.robot);
  WriteU16Le(p + 7, h.to);
  WriteU32Le(p + 9, h.place);
  WriteF32Le(p + 13, h.centre_m.x());
  WriteF32Le(p + 17, h.centre_m.y());
  WriteF32Le(p + 21, h.floor_z_m);
  WriteF32Le(p + 25, h.step_m);
  WriteU32Le(p + 29, static_cast<std::uint32_t>(points.size()));
  std::size_t at = kCloudHeader;
  for (const Eigen::Vector3f& q : points) {
    for (int k = 0; k < 3; ++k) {
      const float units = std::round(q[k] / h.step_m);
      if (!(std::fabs(units) <= 127.0f))
        return Error{Errc::kInvalidArgument, "place cloud: point beyond the quantised range"};
      p[at++] = static_cast<std::uint8_t>(static_cast<std::int8_t>(units));
    }
  }
  WriteU32Le(p + at, Crc32(out.first(at)));
  return at + 4;
}

Expected<PlaceCloudHeader> PeekPlaceCloudHeader(std::span<const std::uint8_t> bytes) {
  if (bytes.size() < kCloudHeader || !MagicIs(bytes, "MSPC"))
    return Error{Errc::kMalformed, "place cloud: not a cloud header"};
  PlaceCloudHeader h;
  h.robot = ReadU16Le(&bytes[5]);
  h.to = ReadU16Le(&bytes[7]);
  h.place = ReadU32Le(&bytes[9]);
  return h;
}

Expected<PlaceCloudHeader> DecodePlaceCloud(std::span<const std::uint8_t> bytes,
                                            BoundedVector<Eigen::Vector3f>& points) {
  points.clear();
  if (auto s = CheckCrc(bytes, kCloudHeader); !s) return s.error();
  if (!MagicIs(bytes, "MSPC")) return Error{Errc::kMalformed, "place cloud: bad magic"};
  if (bytes[4] != kFormat) return Error{Errc::kUnsupported, "place cloud: unknown format"};
  PlaceCloudHeader h;
  h.robot = ReadU16Le(&bytes[5]);
  h.to = ReadU16Le(&bytes[7]);
  h.place = ReadU32Le(&bytes[9]);
  h.centre_m = {ReadF32Le(&bytes[13]), ReadF32Le(&bytes[17])};
  h.floor_z_m = ReadF32Le(&bytes[21]);
  h.step_m = ReadF32Le(&bytes[25]);
  const std::size_t count = ReadU32Le(&bytes[29]);
  if (h.robot == 0 || h.to == 0 || h.robot == h.to)
    return Error{Errc::kMalformed, "place cloud: robot ids must be distinct and non-zero"};
  if (!PlausibleCoordinate(h.centre_m.x()) || !PlausibleCoordinate(h.centre_m.y()) ||
      !PlausibleCoordinate(h.floor_z_m))
    return Error{Errc::kMalformed, "place cloud: centre or floor not finite or implausible"};
  if (!(h.step_m > 0 && h.step_m <= 1.0f)) return Error{Errc::kMalformed, "place cloud: step out of range"};
  if (count > points.capacity())
    return Error{Errc::kCapacityExceeded, "place cloud: more points than the receiver holds"};
  if (bytes.size() != PlaceCloudEncodedSize(count))
    return Error{Errc::kMalformed, "place cloud: length does not match the point count"};
  std::size_t at = kCloudHeader;
  for (std::size_t i = 0; i < count; ++i, at += 3) {
    points.push_back(Eigen::Vector3f(static_cast<float>(static_cast<std::int8_t>(bytes[at])),
                                     static_cast<float>(static_cast<std::int8_t>(bytes[at + 1])),
                                     static_cast<float>(static_cast<std::int8_t>(bytes[at + 2]))) *
                     h.step_m);
  }
  return h;
}

}  // namespace msgraphs::core
