// SPDX-License-Identifier: MIT
#include "msgraphs/drivers/can_odometry/crc8.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstring>

namespace msgraphs::drivers::can_odometry {
namespace {

TEST(Crc8SaeJ1850, CatalogueCheckValue) {
  // The CRC catalogue's check value for CRC-8/SAE-J1850 over ASCII "123456789".
  const char* text = "123456789";
  std::array<std::uint8_t, 9> bytes{};
  std::memcpy(bytes.data(), text, bytes.size());
  EXPECT_EQ(Crc8SaeJ1850(bytes), 0x4B);
}

TEST(Crc8SaeJ1850, EmptyInputIsInitXorOut) { EXPECT_EQ(Crc8SaeJ1850({}), 0x00); }

TEST(Crc8SaeJ1850, DetectsEverySingleBitFlipOfAFrame) {
  std::array<std::uint8_t, 7> frame{0x10, 0x27, 0xF0, 0xD8, 0x64, 0x00, 0x2A};
  const std::uint8_t good = Crc8SaeJ1850(frame);
  for (std::size_t byte = 0; byte < frame.size(); ++byte) {
    for (int bit = 0; bit < 8; ++bit) {
      frame[byte] = static_cast<std::uint8_t>(frame[byte] ^ (1u << bit));
      EXPECT_NE(Crc8SaeJ1850(frame), good) << byte << ":" << bit;
      frame[byte] = static_cast<std::uint8_t>(frame[byte] ^ (1u << bit));
    }
  }
}

}  // namespace
}  // namespace msgraphs::drivers::can_odometry
