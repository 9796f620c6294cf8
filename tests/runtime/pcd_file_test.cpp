// SPDX-License-Identifier: MIT
// The node's PCD maps: what it writes reads back exactly; what other tools write (ascii, extra
// fields, other field orders) reads; malformed files are refused with a reason, never a crash.
#include "msgraphs/runtime/outputs/pcd_file.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

namespace msgraphs::runtime {
namespace {

std::string TempPath(const char* name) {
  return (std::filesystem::temp_directory_path() /
          (std::string("msgraphs_pcd_") + std::to_string(::getpid()) + "_" + name))
      .string();
}

void WriteText(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

TEST(PcdFile, WhatIsWrittenReadsBackBitForBit) {
  const std::string path = TempPath("roundtrip.pcd");
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < 1000; ++i) {
    const float f = static_cast<float>(i);
    points.emplace_back(0.01f * f, -3.5f + f, 1e-3f * f * f);
  }
  ASSERT_TRUE(WritePcd(path, points));
  auto read = ReadPcd(path);
  ASSERT_TRUE(read) << read.error().detail;
  ASSERT_EQ(read->size(), points.size());
  for (std::size_t i = 0; i < points.size(); ++i) EXPECT_EQ((*read)[i], points[i]);
  // The header PCL expects, then exactly 12 bytes a point.
  std::ifstream in(path, std::ios::binary);
  std::string header((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto data = header.find("DATA binary\n");
  ASSERT_NE(data, std::string::npos);
  EXPECT_EQ(header.size() - (data + 12), points.size() * 12);
  EXPECT_NE(header.find("FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 1000\nHEIGHT 1"),
            std::string::npos);
  EXPECT_FALSE(std::filesystem::exists(path + ".tmp"));
  std::remove(path.c_str());
}

TEST(PcdFile, AnEmptyMapIsAValidFile) {
  const std::string path = TempPath("empty.pcd");
  ASSERT_TRUE(WritePcd(path, {}));
  auto read = ReadPcd(path);
  ASSERT_TRUE(read);
  EXPECT_TRUE(read->empty());
  std::remove(path.c_str());
}

TEST(PcdFile, ReadsAsciiWithOtherFieldsAndSkipsNonFinitePoints) {
  const std::string path = TempPath("ascii.pcd");
  WriteText(path,
            "# written by another tool\nVERSION .7\nFIELDS intensity z y x\nSIZE 4 4 4 4\n"
            "TYPE F F F F\nCOUNT 1 1 1 1\nWIDTH 3\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 3\n"
            "DATA ascii\n7 3 2 1\n8 nan 5 4\n9 0.5 -1 2.25\n");
  auto read = ReadPcd(path);
  ASSERT_TRUE(read) << read.error().detail;
  ASSERT_EQ(read->size(), 2u);
  EXPECT_EQ((*read)[0], Eigen::Vector3f(1, 2, 3));
  EXPECT_EQ((*read)[1], Eigen::Vector3f(2.25f, -1, 0.5f));
  std::remove(path.c_str());
}

TEST(PcdFile, ReadsBinaryWithAnIntensityFieldBetween) {
  const std::string path = TempPath("xyzi.pcd");
  std::string text =
      "VERSION .7\nFIELDS x y intensity z\nSIZE 4 4 2 4\nTYPE F F U F\nCOUNT 1 1 1 1\n"
      "WIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA binary\n";
  auto put = [&](float x, float y, std::uint16_t i, float z) {
    text.append(reinterpret_cast<const char*>(&x), 4);
    text.append(reinterpret_cast<const char*>(&y), 4);
    text.append(reinterpret_cast<const char*>(&i), 2);
    text.append(reinterpret_cast<const char*>(&z), 4);
  };
  put(1, 2, 100, 3);
  put(-1, -2, 7, std::numeric_limits<float>::infinity());
  WriteText(path, text);
  auto read = ReadPcd(path);
  ASSERT_TRUE(read) << read.error().detail;
  ASSERT_EQ(read->size(), 1u);
  EXPECT_EQ((*read)[0], Eigen::Vector3f(1, 2, 3));
  std::remove(path.c_str());
}

TEST(PcdFile, RefusesMalformedFilesWithAReason) {
  const std::string path = TempPath("bad.pcd");
  const std::string good_header =
      "VERSION .7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 2\nHEIGHT 1\n"
      "POINTS 2\n";
  const std::pair<std::string, Errc> cases[] = {
      {"", Errc::kMalformed},                                            // empty file
      {good_header, Errc::kMalformed},                                   // no DATA line
      {good_header + "DATA binary\n" + std::string(13, '\0'), Errc::kMalformed},  // truncated
      {good_header + "DATA ascii\n1 2 3\n4 5\n", Errc::kMalformed},      // truncated ascii
      {good_header + "DATA binary_compressed\n", Errc::kUnsupported},
      {"FIELDS x y\nSIZE 4 4\nTYPE F F\nCOUNT 1 1\nPOINTS 1\nDATA ascii\n1 2\n", Errc::kMalformed},
      {"FIELDS x y z\nSIZE 4 4\nTYPE F F F\nPOINTS 1\nDATA ascii\n1 2 3\n", Errc::kMalformed},
      {"FIELDS x y z\nSIZE 8 8 8\nTYPE F F F\nPOINTS 1\nDATA ascii\n1 2 3\n", Errc::kUnsupported},
      {"FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nPOINTS -5\nDATA ascii\n", Errc::kMalformed},
      {"FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 99999999\nPOINTS 1\nDATA ascii\n",
       Errc::kMalformed},
      // A hostile point count: refused (binary) or stopped at the data's end (ascii), never
      // a reservation of gigabytes.
      {"FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nPOINTS 2000000000\nDATA binary\n" +
           std::string(12, '\0'),
       Errc::kMalformed},
      {"FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nPOINTS 2000000000\nDATA ascii\n1 2 3\n",
       Errc::kMalformed},
      // Found by the fuzzer: WIDTH x HEIGHT overflowing when there is no POINTS line.
      {"FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 99999999999999999999999\nHEIGHT 2\n"
       "DATA binary\n",
       Errc::kMalformed},
  };
  for (const auto& [text, code] : cases) {
    WriteText(path, text);
    auto read = ReadPcd(path);
    ASSERT_FALSE(read) << "accepted: " << text.substr(0, 60);
    EXPECT_EQ(read.error().code, code) << read.error().detail << " for: " << text.substr(0, 60);
  }
  EXPECT_FALSE(ReadPcd(TempPath("does_not_exist.pcd")));
  EXPECT_EQ(ReadPcd(TempPath("does_not_exist.pcd")).error().code, Errc::kIo);
  std::remove(path.c_str());
}

TEST(PcdFile, AnUnwritableFolderIsAnIoError) {
  auto s = WritePcd("/nonexistent-folder/map.pcd", {});
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error().code, Errc::kIo);
}

TEST(PcdFile, VoxelKeysSeparateNeighboursAndJoinOneCell) {
  EXPECT_EQ(VoxelKey({0.01f, 0.01f, 0.01f}, 0.05f), VoxelKey({0.04f, 0.02f, 0.0f}, 0.05f));
  EXPECT_NE(VoxelKey({0.01f, 0.01f, 0.01f}, 0.05f), VoxelKey({0.06f, 0.01f, 0.01f}, 0.05f));
  EXPECT_NE(VoxelKey({-0.01f, 0.0f, 0.0f}, 0.05f), VoxelKey({0.01f, 0.0f, 0.0f}, 0.05f));
  EXPECT_NE(VoxelKey({0, 0.06f, 0}, 0.05f), VoxelKey({0, 0, 0.06f}, 0.05f));
}

}  // namespace
}  // namespace msgraphs::runtime
