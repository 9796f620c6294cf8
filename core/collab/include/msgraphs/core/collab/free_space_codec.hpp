// SPDX-License-Identifier: MIT
// The free-space summary on the wire (little-endian, CRC-32 at the end):
//   "MSFS" | format u8 | robot u16 | version u32 | origin x, y f32 | cell f32 | width u16 |
//   height u16 | run count u32 | opening count u16 | runs | openings (a.x, a.y, b.x, b.y f32) |
//   CRC-32
// Cells row by row (x fastest) as runs of one byte each: the state in the top two bits
// (0 unknown, 1 free, 2 occupied; 3 is refused) and the run's length minus one in the low six
// (1..64 cells). A building's summary is mostly long runs: 37,500 cells (100 m x 60 m at 0.4 m)
// take about 3 kB.
// Decoding refuses short or trailing bytes, bad magic, unknown formats, CRC mismatches,
// non-finite or implausible geometry, grids beyond the receiver's max_cells, more openings than
// it holds, an invalid state, and runs that do not add up to width x height, each with a reason.
#pragma once

#include <cstdint>
#include <span>

#include "msgraphs/base/expected.hpp"
#include "msgraphs/core/collab/free_space_summary.hpp"

namespace msgraphs::core {

struct FreeSpaceHeader {
  std::uint16_t robot = 0;
  std::uint32_t version = 0;
};

/// Writes the summary into `out`; kCapacityExceeded when it does not fit. No allocation.
Expected<std::size_t> EncodeFreeSpace(const FreeSpaceHeader& header, const FreeSpaceSummary& summary,
                                      std::span<std::uint8_t> out);
/// Decodes into `summary` (sized by its Init) and computes its clearance. No allocation.
Expected<FreeSpaceHeader> DecodeFreeSpace(std::span<const std::uint8_t> bytes, FreeSpaceSummary& summary);
/// Robot and version, unchecked (no CRC): for a transport that files the message first.
Expected<FreeSpaceHeader> PeekFreeSpaceHeader(std::span<const std::uint8_t> bytes);

}  // namespace msgraphs::core
