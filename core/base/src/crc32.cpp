// SPDX-License-Identifier: MIT
#include "msgraphs/base/crc32.hpp"

#include <array>

namespace msgraphs {
namespace {

// Slicing by 16: kTables[0] is the byte-at-a-time table; kTables[k][b] is the CRC of byte b
// followed by k zero bytes, so 16 bytes are folded with 16 independent lookups (16 kB of tables)
// instead of a chain of 16 dependent ones. The snapshot of an hour's map is 52 MB and is checked at
// every save and load; byte at a time that was 0.11 s of the SLAM thread's keyframe.
using Tables = std::array<std::array<std::uint32_t, 256>, 16>;

constexpr Tables MakeTables() {
  Tables t{};
  for (std::uint32_t i = 0; i < 256; ++i) {
    std::uint32_t c = i;
    for (int k = 0; k < 8; ++k) c = (c & 1u) != 0 ? 0xEDB88320u ^ (c >> 1) : c >> 1;
    t[0][i] = c;
  }
  for (std::size_t k = 1; k < t.size(); ++k)
    for (std::uint32_t i = 0; i < 256; ++i) t[k][i] = (t[k - 1][i] >> 8) ^ t[0][t[k - 1][i] & 0xFFu];
  return t;
}

constexpr Tables kTables = MakeTables();

// Little-endian whatever the host: the CRC is defined on the byte order, not on the CPU's.
inline std::uint32_t Le32(const std::uint8_t* p) {
  return static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 |
         static_cast<std::uint32_t>(p[2]) << 16 | static_cast<std::uint32_t>(p[3]) << 24;
}

}  // namespace

std::uint32_t Crc32(std::span<const std::uint8_t> bytes) noexcept { return Crc32Continue(0, bytes); }

std::uint32_t Crc32Continue(std::uint32_t crc_of_before, std::span<const std::uint8_t> bytes) noexcept {
  std::uint32_t c = crc_of_before ^ 0xFFFFFFFFu;
  const std::uint8_t* p = bytes.data();
  std::size_t n = bytes.size();
  for (; n >= 16; n -= 16, p += 16) {
    const std::uint32_t w0 = Le32(p) ^ c, w1 = Le32(p + 4), w2 = Le32(p + 8), w3 = Le32(p + 12);
    c = kTables[15][w0 & 0xFFu] ^ kTables[14][(w0 >> 8) & 0xFFu] ^ kTables[13][(w0 >> 16) & 0xFFu] ^
        kTables[12][w0 >> 24] ^ kTables[11][w1 & 0xFFu] ^ kTables[10][(w1 >> 8) & 0xFFu] ^
        kTables[9][(w1 >> 16) & 0xFFu] ^ kTables[8][w1 >> 24] ^ kTables[7][w2 & 0xFFu] ^
        kTables[6][(w2 >> 8) & 0xFFu] ^ kTables[5][(w2 >> 16) & 0xFFu] ^ kTables[4][w2 >> 24] ^
        kTables[3][w3 & 0xFFu] ^ kTables[2][(w3 >> 8) & 0xFFu] ^ kTables[1][(w3 >> 16) & 0xFFu] ^
        kTables[0][w3 >> 24];
  }
  for (; n > 0; --n, ++p) c = kTables[0][(c ^ *p) & 0xFFu] ^ (c >> 8);
  return c ^ 0xFFFFFFFFu;
}

}  // namespace msgraphs
