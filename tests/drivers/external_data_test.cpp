// SPDX-License-Identifier: MIT
// Checks that the public data set is reachable through MSGRAPHS_DATA_DIR and is what the
// drivers will be tested against: a real VLP-16 data packet (1206 bytes, 12 firing blocks
// each starting with the 0xFFEE flag, return-mode and product bytes at the end).
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <vector>

#include "test_data.hpp"

namespace msgraphs {
namespace {

TEST(ExternalData, Vlp16SamplePacketHasTheDocumentedLayout) {
  std::filesystem::path path;
  MSGRAPHS_REQUIRE_DATA("pcap/einride_vlp16_packet.bin", path);
  std::ifstream in(path, std::ios::binary);
  const std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)),
                                         std::istreambuf_iterator<char>());
  ASSERT_EQ(bytes.size(), 1206u);
  for (int block = 0; block < 12; ++block) {
    EXPECT_EQ(bytes[static_cast<std::size_t>(block) * 100], 0xFF) << block;
    EXPECT_EQ(bytes[static_cast<std::size_t>(block) * 100 + 1], 0xEE) << block;
  }
  const unsigned char return_mode = bytes[1204];
  EXPECT_TRUE(return_mode == 0x37 || return_mode == 0x38 || return_mode == 0x39) << int{return_mode};
}

}  // namespace
}  // namespace msgraphs
