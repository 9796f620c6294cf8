// SPDX-License-Identifier: MIT
// Builds Velodyne payloads byte by byte for decoder tests, independent of the decoder's code.
#pragma once

#include <array>
#include <cstdint>
#include <cstdio>
#include <vector>

namespace msgraphs::test {

struct TestPacket {
  std::array<std::uint8_t, 1206> bytes{};

  TestPacket(std::uint32_t first_azimuth_cdeg = 0, std::uint32_t step_cdeg = 40,
             std::uint8_t return_mode = 0x37, std::uint8_t product = 0x22) {
    for (int b = 0; b < 12; ++b) {
      SetBlockFlag(b);
      SetAzimuth(b, (first_azimuth_cdeg + static_cast<std::uint32_t>(b) * step_cdeg) % 36000);
    }
    bytes[1204] = return_mode;
    bytes[1205] = product;
  }
  void SetBlockFlag(int block) {
    bytes[static_cast<std::size_t>(block) * 100] = 0xFF;
    bytes[static_cast<std::size_t>(block) * 100 + 1] = 0xEE;
  }
  void SetAzimuth(int block, std::uint32_t cdeg) {
    bytes[static_cast<std::size_t>(block) * 100 + 2] = static_cast<std::uint8_t>(cdeg & 0xFF);
    bytes[static_cast<std::size_t>(block) * 100 + 3] = static_cast<std::uint8_t>(cdeg >> 8);
  }
  void SetChannel(int block, int channel, std::uint16_t distance_2mm, std::uint8_t reflectivity) {
    const std::size_t o = static_cast<std::size_t>(block) * 100 + 4 + static_cast<std::size_t>(channel) * 3;
    bytes[o] = static_cast<std::uint8_t>(distance_2mm & 0xFF);
    bytes[o + 1] = static_cast<std::uint8_t>(distance_2mm >> 8);
    bytes[o + 2] = reflectivity;
  }
  void SetTimestamp(std::uint32_t us) {
    for (int i = 0; i < 4; ++i) bytes[1200 + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(us >> (8 * i));
  }
  void FillAll(std::uint16_t distance_2mm, std::uint8_t reflectivity) {
    for (int b = 0; b < 12; ++b)
      for (int c = 0; c < 32; ++c) SetChannel(b, c, distance_2mm, reflectivity);
  }
};

/// Converts a single-return packet into two dual-return packets as a dual-mode sensor would
/// send them: each firing becomes a (last, strongest) block pair with the same azimuth and
/// both packets carry 6 firings. The strongest copy gets `strongest_delta` added to every
/// non-zero distance (0 = identical returns, which the sensor sends when it saw one return).
inline std::array<std::array<std::uint8_t, 1206>, 2> MakeDualFromSingle(
    const std::array<std::uint8_t, 1206>& single, int strongest_delta, std::uint32_t second_timestamp_us) {
  std::array<std::array<std::uint8_t, 1206>, 2> out{};
  for (int half = 0; half < 2; ++half) {
    auto& p = out[static_cast<std::size_t>(half)];
    for (int f = 0; f < 6; ++f) {
      const std::uint8_t* src = single.data() + static_cast<std::size_t>(half * 6 + f) * 100;
      for (int copy = 0; copy < 2; ++copy) {
        std::uint8_t* dst = p.data() + static_cast<std::size_t>(2 * f + copy) * 100;
        for (int i = 0; i < 100; ++i) dst[i] = src[i];
        if (copy == 1 && strongest_delta != 0) {
          for (int c = 0; c < 32; ++c) {
            std::uint8_t* rec = dst + 4 + c * 3;
            const int d = rec[0] | (rec[1] << 8);
            if (d == 0) continue;
            const int nd = d + strongest_delta;
            rec[0] = static_cast<std::uint8_t>(nd & 0xFF);
            rec[1] = static_cast<std::uint8_t>(nd >> 8);
          }
        }
      }
    }
    for (int i = 1200; i < 1206; ++i) p[static_cast<std::size_t>(i)] = single[static_cast<std::size_t>(i)];
    p[1204] = 0x39;
  }
  for (int i = 0; i < 4; ++i) out[1][1200 + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(second_timestamp_us >> (8 * i));
  return out;
}

inline std::vector<std::uint8_t> ReadFileBytes(const char* path) {
  std::vector<std::uint8_t> bytes;
  if (FILE* f = std::fopen(path, "rb")) {
    std::uint8_t buffer[65536];
    std::size_t n = 0;
    while ((n = std::fread(buffer, 1, sizeof(buffer), f)) > 0) bytes.insert(bytes.end(), buffer, buffer + n);
    std::fclose(f);
  }
  return bytes;
}

}  // namespace msgraphs::test
