// SPDX-License-Identifier: MIT
#include "msgraphs/core/collab/room_messages.hpp"

#include <array>
#include <cmath>
#include <cstring>

#include "msgraphs/base/byte_order.hpp"
#include "msgraphs/base/crc32.hpp"

namespace msgraphs::core {
namespace {

constexpr std::uint8_t kFormat = 1;
// Descriptors: format 2 adds the height step (cm per unit: rooms up to 2.55 m at 1 cm, taller
// ones coarser); format 1 (1 cm, 21-byte header) is still read.
constexpr std::uint8_t kDescriptorFormat = 2;
constexpr std::size_t kDescriptorHeaderV1 = 4 + 1 + 2 + 4 + 4 + 1 + 1 + 4;  // 21
constexpr std::size_t kDescriptorHeader = kDescriptorHeaderV1 + 1;         // 22
constexpr std::size_t kCloudHeader = 4 + 1 + 1 + 2 + 4 + 4 + 4 + 4;       // 24

bool MagicIs(std::span<const std::uint8_t> b, const char* m) {
  return std::memcmp(b.data(), m, 4) == 0;
}

Status CheckCrc(std::span<const std::uint8_t> bytes, std::size_t header) {
  if (bytes.size() < header + 4)
    return Error{Errc::kMalformed, "room message: shorter than its header"};
  const std::size_t body = bytes.size() - 4;
  if (ReadU32Le(&bytes[body]) != Crc32(bytes.first(body)))
    return Error{Errc::kChecksum, "room message: CRC mismatch"};
  return Ok();
}

}  // namespace

std::size_t RoomDescriptorEncodedSize(const ScanContext& d) {
  return RoomDescriptorEncodedSize(d.rings(), d.sectors());
}

std::size_t RoomDescriptorEncodedSize(int rings, int sectors) {
  return kDescriptorHeader + static_cast<std::size_t>(rings * sectors) + 4;
}

Expected<std::size_t> EncodeRoomDescriptor(const RoomDescriptorHeader& h,
                                           const ScanContext& d,
                                           std::span<std::uint8_t> out) {
  const std::size_t size = RoomDescriptorEncodedSize(d);
  if (size > out.size())
    return Error{Errc::kCapacityExceeded, "room descriptor: output buffer too small"};
  std::uint8_t* p = out.data();
  std::memcpy(p, "MSRD", 4);
  p[4] = kDescriptorFormat;
  WriteU16Le(p + 5, h.robot);
  WriteU32Le(p + 7, h.room);
  WriteU32Le(p + 11, h.version);
  p[15] = static_cast<std::uint8_t>(d.rings());
  p[16] = static_cast<std::uint8_t>(d.sectors());
  WriteF32Le(p + 17, d.max_radius_m());
  // The finest whole-centimetre step at which the tallest cell fits 255 units (20 m at most).
  float tallest = 0;
  for (int r = 0; r < d.rings(); ++r)
    for (int s = 0; s < d.sectors(); ++s) tallest = std::max(tallest, d.cell(r, s));
  const int step_cm = std::clamp(static_cast<int>(std::ceil(tallest * 100.0f / 255.0f)), 1, 8);
  p[21] = static_cast<std::uint8_t>(step_cm);
  const float step_m = 0.01f * static_cast<float>(step_cm);
  std::size_t at = kDescriptorHeader;
  for (int r = 0; r < d.rings(); ++r) {
    for (int s = 0; s < d.sectors(); ++s, ++at) {
      const float units = std::round(std::clamp(d.cell(r, s), 0.0f, 255.0f * step_m) / step_m);
      p[at] = static_cast<std::uint8_t>(units);
    }
  }
  WriteU32Le(p + at, Crc32(out.first(at)));
  return at + 4;
}

Expected<RoomDescriptorHeader> DecodeRoomDescriptor(std::span<const std::uint8_t> bytes,
                                                    ScanContext& d) {
  if (auto s = CheckCrc(bytes, kDescriptorHeaderV1); !s) return s.error();
  if (!MagicIs(bytes, "MSRD")) return Error{Errc::kMalformed, "room descriptor: bad magic"};
  if (bytes[4] != 1 && bytes[4] != kDescriptorFormat)
    return Error{Errc::kUnsupported, "room descriptor: unknown format"};
  const std::size_t header = bytes[4] == 1 ? kDescriptorHeaderV1 : kDescriptorHeader;
  if (bytes.size() < header + 4) return Error{Errc::kMalformed, "room descriptor: shorter than its header"};
  const int step_cm = bytes[4] == 1 ? 1 : bytes[21];
  if (step_cm < 1 || step_cm > 8) return Error{Errc::kMalformed, "room descriptor: height step out of range"};
  RoomDescriptorHeader h;
  h.robot = ReadU16Le(&bytes[5]);
  h.room = ReadU32Le(&bytes[7]);
  h.version = ReadU32Le(&bytes[11]);
  const int rings = bytes[15], sectors = bytes[16];
  const float radius = ReadF32Le(&bytes[17]);
  if (rings < 1 || sectors < 1 || rings > ScanContext::kMaxRings ||
      sectors > ScanContext::kMaxSectors) {
    return Error{Errc::kMalformed, "room descriptor: rings or sectors out of range"};
  }
  if (bytes.size() != header + static_cast<std::size_t>(rings * sectors) + 4) {
    return Error{Errc::kMalformed, "room descriptor: length does not match rings x sectors"};
  }
  std::array<float, ScanContext::kMaxRings * ScanContext::kMaxSectors> cells{};
  for (std::size_t i = 0; i < static_cast<std::size_t>(rings * sectors); ++i) {
    cells[i] = static_cast<float>(bytes[header + i]) * 0.01f * static_cast<float>(step_cm);
  }
  if (auto s = d.FromCells(
          rings, sectors, radius,
          std::span<const float>(cells.data(), static_cast<std::size_t>(rings * sectors)));
      !s) {
    return s.error();
  }
  return h;
}

Expected<RoomDescriptorHeader> PeekRoomDescriptorHeader(std::span<const std::uint8_t> bytes) {
  if (bytes.size() < kDescriptorHeader || !MagicIs(bytes, "MSRD"))
    return Error{Errc::kMalformed, "room descriptor: not a descriptor header"};
  return RoomDescriptorHeader{ReadU16Le(&bytes[5]), ReadU32Le(&bytes[7]), ReadU32Le(&bytes[11])};
}

Expected<RoomCloudHeader> PeekRoomCloudHeader(std::span<const std::uint8_t> bytes) {
  if (bytes.size() < kCloudHeader || !MagicIs(bytes, "MSRC"))
    return Error{Errc::kMalformed, "room cloud: not a cloud header"};
  RoomCloudHeader h;
  h.robot = ReadU16Le(&bytes[6]);
  h.room = ReadU32Le(&bytes[8]);
  h.version = ReadU32Le(&bytes[12]);
  return h;
}

std::size_t RoomCloudEncodedSize(CloudEncoding encoding, std::size_t points) {
  const std::size_t per_point = encoding == CloudEncoding::kFloat32       ? 12u
                                : encoding == CloudEncoding::kQuantised16 ? 6u
                                                                          : 3u;
  return kCloudHeader + points * per_point + 4;
}

Expected<std::size_t> EncodeRoomCloud(const RoomCloudHeader& h,
                                      std::span<const Eigen::Vector3f> points,
                                      std::span<std::uint8_t> out) {
  if (h.encoding != CloudEncoding::kFloat32 && h.encoding != CloudEncoding::kQuantised16 &&
      h.encoding != CloudEncoding::kQuantised8) {
    return Error{Errc::kInvalidArgument, "room cloud: unknown encoding"};
  }
  if (h.encoding != CloudEncoding::kFloat32 && !(h.step_m > 0))
    return Error{Errc::kInvalidArgument, "room cloud: step must be positive"};
  const std::size_t size = RoomCloudEncodedSize(h.encoding, points.size());
  if (size > out.size())
    return Error{Errc::kCapacityExceeded, "room cloud: output buffer too small"};
  std::uint8_t* p = out.data();
  std::memcpy(p, "MSRC", 4);
  p[4] = kFormat;
  p[5] = static_cast<std::uint8_t>(h.encoding);
  WriteU16Le(p + 6, h.robot);
  WriteU32Le(p + 8, h.room);
  WriteU32Le(p + 12, h.version);
  WriteF32Le(p + 16, h.step_m);
  WriteU32Le(p + 20, static_cast<std::uint32_t>(points.size()));
  std::size_t at = kCloudHeader;
  for (const Eigen::Vector3f& q : points) {
    for (int k = 0; k < 3; ++k) {
      if (h.encoding == CloudEncoding::kFloat32) {
        WriteF32Le(p + at, q[k]);
        at += 4;
      } else if (h.encoding == CloudEncoding::kQuantised16) {
        const float units = std::round(q[k] / h.step_m);
        if (!(std::fabs(units) <= 32767.0f))
          return Error{Errc::kInvalidArgument, "room cloud: point beyond the quantised range"};
        WriteU16Le(p + at, static_cast<std::uint16_t>(static_cast<std::int16_t>(units)));
        at += 2;
      } else {
        const float units = std::round(q[k] / h.step_m);
        if (!(std::fabs(units) <= 127.0f))
          return Error{Errc::kInvalidArgument, "room cloud: point beyond the quantised range"};
        p[at] = static_cast<std::uint8_t>(static_cast<std::int8_t>(units));
        at += 1;
      }
    }
  }
  WriteU32Le(p + at, Crc32(out.first(at)));
  return at + 4;
}

Expected<RoomCloudHeader> DecodeRoomCloud(std::span<const std::uint8_t> bytes,
                                          BoundedVector<Eigen::Vector3f>& points) {
  points.clear();
  if (auto s = CheckCrc(bytes, kCloudHeader); !s) return s.error();
  if (!MagicIs(bytes, "MSRC")) return Error{Errc::kMalformed, "room cloud: bad magic"};
  if (bytes[4] != kFormat) return Error{Errc::kUnsupported, "room cloud: unknown format"};
  if (bytes[5] > 2) return Error{Errc::kMalformed, "room cloud: unknown encoding"};
  RoomCloudHeader h;
  h.encoding = static_cast<CloudEncoding>(bytes[5]);
  h.robot = ReadU16Le(&bytes[6]);
  h.room = ReadU32Le(&bytes[8]);
  h.version = ReadU32Le(&bytes[12]);
  h.step_m = ReadF32Le(&bytes[16]);
  const std::size_t count = ReadU32Le(&bytes[20]);
  if (h.encoding != CloudEncoding::kFloat32 && !(h.step_m > 0 && std::isfinite(h.step_m))) {
    return Error{Errc::kMalformed, "room cloud: bad quantisation step"};
  }
  if (count > points.capacity())
    return Error{Errc::kCapacityExceeded, "room cloud: more points than the receiver holds"};
  if (bytes.size() != RoomCloudEncodedSize(h.encoding, count))
    return Error{Errc::kMalformed, "room cloud: length does not match the point count"};
  std::size_t at = kCloudHeader;
  for (std::size_t i = 0; i < count; ++i) {
    Eigen::Vector3f q;
    for (int k = 0; k < 3; ++k) {
      if (h.encoding == CloudEncoding::kFloat32) {
        q[k] = ReadF32Le(&bytes[at]);
        at += 4;
      } else if (h.encoding == CloudEncoding::kQuantised16) {
        q[k] = static_cast<float>(static_cast<std::int16_t>(ReadU16Le(&bytes[at]))) * h.step_m;
        at += 2;
      } else {
        q[k] = static_cast<float>(static_cast<std::int8_t>(bytes[at])) * h.step_m;
        at += 1;
      }
    }
    if (!q.allFinite()) {
      points.clear();
      return Error{Errc::kMalformed, "room cloud: point not finite"};
    }
    points.push_back(q);
  }
  return h;
}

Expected<std::size_t> EncodeRoomCloudRequest(const RoomCloudRequest& q,
                                             std::span<std::uint8_t> out) {
  if (out.size() < kRoomCloudRequestBytes)
    return Error{Errc::kCapacityExceeded, "room cloud request: output buffer too small"};
  std::uint8_t* p = out.data();
  std::memcpy(p, "MSRQ", 4);
  p[4] = kFormat;
  WriteU16Le(p + 5, q.from);
  WriteU16Le(p + 7, q.to);
  WriteU32Le(p + 9, q.room);
  WriteU32Le(p + 13, q.version);
  WriteU32Le(p + 17, Crc32(out.first(17)));
  return kRoomCloudRequestBytes;
}

Expected<RoomCloudRequest> DecodeRoomCloudRequest(std::span<const std::uint8_t> bytes) {
  if (auto s = CheckCrc(bytes, kRoomCloudRequestBytes - 4); !s) return s.error();
  if (bytes.size() != kRoomCloudRequestBytes)
    return Error{Errc::kMalformed, "room cloud request: wrong length"};
  if (!MagicIs(bytes, "MSRQ")) return Error{Errc::kMalformed, "room cloud request: bad magic"};
  if (bytes[4] != kFormat) return Error{Errc::kUnsupported, "room cloud request: unknown format"};
  RoomCloudRequest q;
  q.from = ReadU16Le(&bytes[5]);
  q.to = ReadU16Le(&bytes[7]);
  q.room = ReadU32Le(&bytes[9]);
  q.version = ReadU32Le(&bytes[13]);
  if (q.from == 0 || q.to == 0 || q.from == q.to)
    return Error{Errc::kMalformed, "room cloud request: robot ids must be distinct and non-zero"};
  return q;
}

}  // namespace msgraphs::core
