// SPDX-License-Identifier: MIT
// candump log lines (`candump -l` files, `candump -L` output), the format can-utils' canplayer
// replays: "(1700000000.123456) can0 120#1A2B3C4D5E6F7788 [R|T]". Timestamps with 6 or 9
// decimals, as canplayer accepts. Pure parsing and formatting; files are in candump_file.hpp.
#pragma once

#include <array>
#include <cstddef>
#include <span>
#include <string_view>

#include "msgraphs/base/expected.hpp"
#include "msgraphs/base/time.hpp"
#include "msgraphs/drivers/can_odometry/can_frame.hpp"

namespace msgraphs::drivers::can_odometry {

inline constexpr std::size_t kMaxInterfaceName = 16;  // IFNAMSIZ, NUL included

struct CandumpLine {
  enum class Kind : std::uint8_t {
    kFrame,    ///< a classic CAN frame: `stamp`, `interface`, `frame` are set
    kComment,  ///< blank or not starting with '(' (canplayer skips these too)
    kCanFd,    ///< a well-formed CAN FD frame: skipped by odometry, counted by callers
    kCanXl,    ///< a well-formed CAN XL frame: skipped likewise
  } kind = Kind::kComment;
  UnixTime stamp;
  std::array<char, kMaxInterfaceName> interface{};
  CanFrame frame;

  std::string_view interface_name() const { return {interface.data()}; }
};

/// Parses one line (without or with its trailing newline). kMalformed with a reason for lines
/// that start like a record but break the grammar (bad timestamp, id, data, length).
Expected<CandumpLine> ParseCandumpLine(std::string_view line);

enum class CandumpPrecision : std::uint8_t { kMicroseconds = 6, kNanoseconds = 9 };

/// Writes "(sec.frac) iface ID#DATA\n" into `out` (hex upper case, as candump does). Returns
/// the length; kCapacityExceeded when `out` is shorter than kMaxCandumpLine.
inline constexpr std::size_t kMaxCandumpLine = 96;
Expected<std::size_t> FormatCandumpLine(UnixTime stamp, std::string_view interface,
                                        const CanFrame& frame, CandumpPrecision precision,
                                        std::span<char> out);

}  // namespace msgraphs::drivers::can_odometry
