// SPDX-License-Identifier: MIT
#include "msgraphs/core/collab/free_space_codec.hpp"

#include <cmath>
#include <cstring>

#include "msgraphs/base/byte_order.hpp"
#include "msgraphs/base/crc32.hpp"

namespace msgraphs::core {
namespace {

constexpr std::uint8_t kFormat = 1;
constexpr std::size_t kHeader = 4 + 1 + 2 + 4 + 4 + 4 + 4 + 2 + 2 + 4 + 2;  // 33
constexpr std::size_t kOpeningBytes = 16;
constexpr int kMaxRun = 64;


}  // namespace

Expected<std::size_t> EncodeFreeSpace(const FreeSpaceHeader& h, const FreeSpaceSummary& summary,
                                      std::span<std::uint8_t> out) {
  if (summary.width() > 0xFFFF || summary.height() > 0xFFFF || summary.openings().size() > 0xFFFF)
    return Error{Errc::kInvalidArgument, "free space: grid wider than 65535 cells"};
  if (out.size() < kHeader + 4)
    return Error{Errc::kCapacityExceeded, "free space: output buffer too small"};
  std::uint8_t* p = out.data();
  std::memcpy(p, "MSFS", 4);
  p[4] = kFormat;
  WriteU16Le(p + 5, h.robot);
  WriteU32Le(p + 7, h.version);
  WriteF32Le(p + 11, static_cast<float>(summary.origin_m().x()));
  WriteF32Le(p + 15, static_cast<float>(summary.origin_m().y()));
  WriteF32Le(p + 19, summary.cell_m());
  WriteU16Le(p + 23, static_cast<std::uint16_t>(summary.width()));
  WriteU16Le(p + 25, static_cast<std::uint16_t>(summary.height()));
  std::size_t at = kHeader;
  std::uint32_t runs = 0;
  const std::span<const std::uint8_t> cells = summary.raw();
  for (std::size_t i = 0; i < cells.size();) {
    const std::uint8_t state = cells[i];
    int length = 1;
    while (length < kMaxRun && i + static_cast<std::size_t>(length) < cells.size() &&
           cells[i + static_cast<std::size_t>(length)] == state) {
      ++length;
    }
    if (at + 1 + 4 > out.size())
      return Error{Errc::kCapacityExceeded, "free space: output buffer too small"};
    p[at++] = static_cast<std::uint8_t>((state << 6) | (length - 1));
    ++runs;
    i += static_cast<std::size_t>(length);
  }
  WriteU32Le(p + 27, runs);
  WriteU16Le(p + 31, static_cast<std::uint16_t>(summary.openings().size()));
  if (at + summary.openings().size() * kOpeningBytes + 4 > out.size())
    return Error{Errc::kCapacityExceeded, "free space: output buffer too small"};
  for (const Opening& o : summary.openings()) {
    WriteF32Le(p + at, static_cast<float>(o.a.x()));
    WriteF32Le(p + at + 4, static_cast<float>(o.a.y()));
    WriteF32Le(p + at + 8, static_cast<float>(o.b.x()));
    WriteF32Le(p + at + 12, static_cast<float>(o.b.y()));
    at += kOpeningBytes;
  }
  WriteU32Le(p + at, Crc32(out.first(at)));
  return at + 4;
}

Expected<FreeSpaceHeader> PeekFreeSpaceHeader(std::span<const std::uint8_t> bytes) {
  if (bytes.size() < kHeader || std::memcmp(bytes.data(), "MSFS", 4) != 0)
    return Error{Errc::kMalformed, "free space: not a free-space header"};
  return FreeSpaceHeader{ReadU16Le(&bytes[5]), ReadU32Le(&bytes[7])};
}

Expected<FreeSpaceHeader> DecodeFreeSpace(std::span<const std::uint8_t> bytes,
                                          FreeSpaceSummary& summary) {
  if (bytes.size() < kHeader + 4)
    return Error{Errc::kMalformed, "free space: shorter than its header"};
  const std::size_t body = bytes.size() - 4;
  if (ReadU32Le(&bytes[body]) != Crc32(bytes.first(body)))
    return Error{Errc::kChecksum, "free space: CRC mismatch"};
  if (std::memcmp(bytes.data(), "MSFS", 4) != 0)
    return Error{Errc::kMalformed, "free space: bad magic"};
  if (bytes[4] != kFormat) return Error{Errc::kUnsupported, "free space: unknown format"};
  FreeSpaceHeader h{ReadU16Le(&bytes[5]), ReadU32Le(&bytes[7])};
  const Eigen::Vector2d origin(ReadF32Le(&bytes[11]), ReadF32Le(&bytes[15]));
  const float cell = ReadF32Le(&bytes[19]);
  const int width = ReadU16Le(&bytes[23]), height = ReadU16Le(&bytes[25]);
  const std::uint32_t runs = ReadU32Le(&bytes[27]);
  const std::size_t openings = ReadU16Le(&bytes[31]);
  // A map frame is the robot's first pose: anything beyond 100 km is not a building.
  if (!origin.allFinite() || origin.cwiseAbs().maxCoeff() > 1e5 || !std::isfinite(cell))
    return Error{Errc::kMalformed, "free space: origin or cell not finite or implausible"};
  if (static_cast<std::size_t>(runs) + openings * kOpeningBytes != body - kHeader)
    return Error{Errc::kMalformed, "free space: run and opening counts do not match the length"};
  if (openings > summary.config().max_openings)
    return Error{Errc::kCapacityExceeded, "free space: more openings than max_openings"};
  if (auto s = summary.Reset(origin, cell, width, height); !s) return s.error();
  const std::size_t total = summary.cells();
  const std::size_t runs_end = kHeader + runs;
  std::size_t at = 0;
  for (std::size_t i = kHeader; i < runs_end; ++i) {
    const std::uint8_t state = bytes[i] >> 6;
    const std::size_t length = static_cast<std::size_t>(bytes[i] & 0x3F) + 1;
    if (state > 2) return Error{Errc::kMalformed, "free space: invalid cell state"};
    if (at + length > total) return Error{Errc::kMalformed, "free space: runs exceed the grid"};
    for (std::size_t k = 0; k < length; ++k) summary.set(at + k, static_cast<SummaryCell>(state));
    at += length;
  }
  if (at != total) return Error{Errc::kMalformed, "free space: runs do not fill the grid"};
  for (std::size_t i = runs_end; i < body; i += kOpeningBytes) {
    const Opening o{{ReadF32Le(&bytes[i]), ReadF32Le(&bytes[i + 4])}, {ReadF32Le(&bytes[i + 8]), ReadF32Le(&bytes[i + 12])}};
    if (!o.a.allFinite() || !o.b.allFinite() || o.a.cwiseAbs().maxCoeff() > 1e5 ||
        o.b.cwiseAbs().maxCoeff() > 1e5 || (o.b - o.a).norm() > 100.0) {
      return Error{Errc::kMalformed, "free space: opening not finite or implausible"};
    }
    static_cast<void>(summary.add_opening(o));  // counted against max_openings above
  }
  summary.ComputeClearance();
  return h;
}

}  // namespace msgraphs::core
