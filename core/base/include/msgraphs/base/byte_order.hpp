// SPDX-License-Identifier: MIT
// Little-endian reads and writes at any alignment, independent of the host's byte order: the
// wire formats (Velodyne packets, pcap records, CAN signals) are all little-endian.
#pragma once

#include <cstdint>
#include <cstring>

namespace msgraphs {

inline std::uint16_t ReadU16Le(const std::uint8_t* p) {
  return static_cast<std::uint16_t>(p[0] | (p[1] << 8));
}
inline std::uint32_t ReadU32Le(const std::uint8_t* p) {
  return static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8) |
         (static_cast<std::uint32_t>(p[2]) << 16) | (static_cast<std::uint32_t>(p[3]) << 24);
}
inline void WriteU16Le(std::uint8_t* p, std::uint16_t v) {
  p[0] = static_cast<std::uint8_t>(v & 0xFFu);
  p[1] = static_cast<std::uint8_t>(v >> 8);
}
inline void WriteU32Le(std::uint8_t* p, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<std::uint8_t>((v >> (8 * i)) & 0xFFu);
}
/// IEEE-754 binary32, little-endian (the collab messages' coordinates).
inline void WriteF32Le(std::uint8_t* p, float f) {
  std::uint32_t u;
  std::memcpy(&u, &f, 4);
  WriteU32Le(p, u);
}
inline float ReadF32Le(const std::uint8_t* p) {
  const std::uint32_t u = ReadU32Le(p);
  float f;
  std::memcpy(&f, &u, 4);
  return f;
}

}  // namespace msgraphs
