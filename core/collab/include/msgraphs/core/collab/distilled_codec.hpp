// SPDX-License-Identifier: MIT
// The distilled S-Graph on the wire: compact, versioned, incremental, checked.
//
// Little-endian layout (format 1):
//   "MSDG" | format u8 | flags u8 (bit 0: floor) | robot u16 | version u32 | since u32 |
//   walls u16 | rooms u16 | [floor x, y, height z: f32 x3] |
//   wall  x walls: id u32, version u32, normal f32 x3, d f32, covariance f32 x6 (xx xy xz yy yz
//   zz),
//                  extent a, b f32 x4                                      (64 bytes)
//   room  x rooms: id u32, version u32, shape u8, centre f32 x2, yaw f32, size f32 x2,
//                  walls i32 x4                                             (45 bytes)
//   CRC-32 (IEEE) of everything before it.
// Only elements whose version is above `since` are written: a delta against what the receiver
// acknowledged (since = 0: everything). Metres and radians in f32 keep 10 um at 100 m.
//
// Decoding rejects, with a reason: short or trailing bytes, bad magic, unknown format, a CRC
// mismatch, more elements than the receiver's capacity, non-finite numbers, non-unit normals,
// covariances that are not symmetric positive definite, unknown room shapes, rooms whose walls
// are neither in the message nor already known. Nothing allocates.
#pragma once

#include <cstdint>
#include <span>

#include "msgraphs/base/expected.hpp"
#include "msgraphs/core/graph/distilled_graph.hpp"

namespace msgraphs::core {

inline constexpr std::size_t kDistilledHeaderBytes = 20;
inline constexpr std::size_t kDistilledWallBytes = 64;
inline constexpr std::size_t kDistilledRoomBytes = 45;
inline constexpr std::size_t kDistilledFloorBytes = 12;

/// Bytes EncodeDistilled needs for `graph` since `since`.
std::size_t DistilledEncodedSize(const DistilledGraph& graph, std::uint32_t since);

/// Writes the delta into `out`; kCapacityExceeded when it does not fit. Returns bytes written.
Expected<std::size_t> EncodeDistilled(const DistilledGraph& graph,
                                      std::uint32_t since,
                                      std::span<std::uint8_t> out);

struct DistilledDelta {
  std::uint32_t since = 0;
};

/// Decodes into `out` (cleared; its capacities are the limits). `known` (optional) is the
/// receiver's current copy of this robot's graph: rooms may refer to walls it already holds.
Expected<DistilledDelta> DecodeDistilled(std::span<const std::uint8_t> bytes,
                                         DistilledGraph& out,
                                         const DistilledGraph* known = nullptr);

/// The sending robot's id from a message's header (before decoding it against that robot's
/// copy), once magic and CRC are right: kMalformed (short, bad magic) or kChecksum otherwise.
Expected<std::uint16_t> DistilledSender(std::span<const std::uint8_t> bytes);

/// Merges a decoded delta into the receiver's copy (upsert by id). kCapacityExceeded (what fit
/// is kept) when the copy is full.
Status ApplyDistilled(const DistilledGraph& delta, DistilledGraph& copy);

}  // namespace msgraphs::core
