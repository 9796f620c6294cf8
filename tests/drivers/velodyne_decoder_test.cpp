// SPDX-License-Identifier: MIT
// Velodyne data and position packet decoding from hand-built bytes: geometry, timing, azimuth
// interpolation, return modes, rejection of malformed packets, zero allocation per packet.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <numbers>
#include <string>
#include <vector>

#include "alloc_counter.hpp"
#include "msgraphs/drivers/velodyne/data_packet_decoder.hpp"
#include "msgraphs/drivers/velodyne/position_packet.hpp"
#include "velodyne_test_packets.hpp"

namespace msgraphs::drivers::velodyne {
namespace {

using test::TestPacket;
constexpr double kDeg = std::numbers::pi / 180.0;

DataPacketDecoder MakeDecoder(DecoderConfig config = {}) {
  auto decoder = DataPacketDecoder::Create(config);
  EXPECT_TRUE(decoder.has_value());
  return std::move(decoder).value();
}

const VelodynePoint* FindPoint(std::span<const VelodynePoint> points, int laser, std::uint32_t time_ns) {
  for (const auto& p : points) {
    if (p.laser_id == laser && p.time_offset_ns == time_ns) return &p;
  }
  return nullptr;
}

TEST(VelodyneDecoder, PointGeometryFollowsTheRosLidarFrame) {
  TestPacket packet(0, 40);
  packet.SetChannel(0, 0, 5000, 77);  // laser 0: -15 deg, 10 m, azimuth 0
  packet.SetChannel(3, 1, 2500, 5);   // laser 1: +1 deg, 5 m, block 3 azimuth 120 cdeg
  const auto decoder = MakeDecoder();
  std::vector<VelodynePoint> out(kMaxPointsPerPacket);
  auto result = decoder.Decode(packet.bytes, out);
  ASSERT_TRUE(result.has_value());
  ASSERT_EQ(result->points, 2);
  EXPECT_EQ(result->no_return, 384 - 2);

  const VelodynePoint& a = out[0];
  EXPECT_EQ(a.laser_id, 0);
  EXPECT_EQ(a.ring, 0);
  EXPECT_EQ(a.intensity, 77);
  EXPECT_EQ(a.azimuth_cdeg, 0);
  EXPECT_NEAR(a.range_m, 10.0, 1e-6);
  EXPECT_NEAR(a.x_m, 10.0 * std::cos(15 * kDeg), 1e-5);
  EXPECT_NEAR(a.y_m, 0.0, 1e-5);
  EXPECT_NEAR(a.z_m, -10.0 * std::sin(15 * kDeg) + 0.0112, 1e-5);  // manual offset, laser 0

  // Laser 1 fires 2.304 us after laser 0: the azimuth is interpolated inside the block.
  const VelodynePoint& b = out[1];
  EXPECT_EQ(b.laser_id, 1);
  EXPECT_EQ(b.ring, 8);
  const std::uint32_t t = 3 * 110592 + 2304;
  EXPECT_EQ(b.time_offset_ns, t);
  const double azimuth_deg = (120 + 40.0 * 2304 / 110592) / 100.0;
  EXPECT_EQ(b.azimuth_cdeg, 121);
  const double xy = 5.0 * std::cos(1 * kDeg);
  // Clockwise azimuth seen from above: positive azimuth moves the point to the right (-y).
  EXPECT_NEAR(b.x_m, xy * std::cos(1.21 * kDeg), 1e-4);
  EXPECT_NEAR(b.y_m, -xy * std::sin(1.21 * kDeg), 1e-4);
  EXPECT_NEAR(azimuth_deg, 1.2083, 1e-3);
}

TEST(VelodyneDecoder, Vlp16FiringTimingAndRingsMatchTheManual) {
  TestPacket packet(1000, 40);
  packet.FillAll(1000, 1);
  const auto decoder = MakeDecoder();
  std::vector<VelodynePoint> out(kMaxPointsPerPacket);
  auto result = decoder.Decode(packet.bytes, out);
  ASSERT_TRUE(result.has_value());
  ASSERT_EQ(result->points, 384);
  EXPECT_EQ(result->packet_duration_ns, 1327104u);
  // Block 3, channel 20 = second firing sequence, laser 4.
  const VelodynePoint* p = FindPoint(out, 4, 3 * 110592 + 55296 + 4 * 2304);
  ASSERT_NE(p, nullptr);
  // Sequence 2 of block 0 fires half a block later: half a step further round.
  const VelodynePoint* q = FindPoint(out, 0, 55296);
  ASSERT_NE(q, nullptr);
  EXPECT_EQ(q->azimuth_cdeg, 1020);
  // The last block reuses the previous step (no successor inside the packet).
  const VelodynePoint* last = FindPoint(out, 0, 11 * 110592 + 55296);
  ASSERT_NE(last, nullptr);
  EXPECT_EQ(last->azimuth_cdeg, 1000 + 11 * 40 + 20);
  // Rings sort by elevation: -15 (laser 0) is 0, +15 (laser 15) is 15, +1 (laser 1) is 8.
  const auto& info = decoder.model();
  EXPECT_EQ(info.laser[0].ring, 0);
  EXPECT_EQ(info.laser[15].ring, 15);
  EXPECT_EQ(info.laser[14].ring, 7);
  EXPECT_EQ(info.laser[1].ring, 8);
  // Times are non-decreasing in channel order within a block.
  for (std::size_t i = 1; i < 32; ++i) EXPECT_GT(out[i].time_offset_ns, out[i - 1].time_offset_ns);
}

TEST(VelodyneDecoder, AzimuthInterpolationWrapsAt36000) {
  TestPacket packet(35980, 40);
  packet.FillAll(1000, 1);
  const auto decoder = MakeDecoder();
  std::vector<VelodynePoint> out(kMaxPointsPerPacket);
  auto result = decoder.Decode(packet.bytes, out);
  ASSERT_TRUE(result.has_value());
  const VelodynePoint* p = FindPoint(out, 0, 55296);  // block 0, sequence 2: 35980 + 20
  ASSERT_NE(p, nullptr);
  EXPECT_EQ(p->azimuth_cdeg, 0);
  for (const auto& point : out) EXPECT_LT(point.azimuth_cdeg, 36000);
}

TEST(VelodyneDecoder, Hdl32eTimingAndElevations) {
  TestPacket packet(0, 17, 0x37, 0x21);
  packet.FillAll(1000, 1);
  DecoderConfig config;
  config.model = SensorModel::kHdl32e;
  const auto decoder = MakeDecoder(config);
  std::vector<VelodynePoint> out(kMaxPointsPerPacket);
  auto result = decoder.Decode(packet.bytes, out);
  ASSERT_TRUE(result.has_value());
  EXPECT_EQ(result->packet_duration_ns, 12u * 46080u);
  const VelodynePoint* p = FindPoint(out, 5, 2 * 46080 + 2 * 1152);
  ASSERT_NE(p, nullptr);
  EXPECT_NEAR(decoder.model().laser[0].elevation_rad, -30.67 * kDeg, 1e-3);
  EXPECT_NEAR(decoder.model().laser[31].elevation_rad, 10.67 * kDeg, 1e-3);
  EXPECT_EQ(decoder.model().laser[0].ring, 0);
  EXPECT_EQ(decoder.model().laser[31].ring, 31);
}

TEST(VelodyneDecoder, LastReturnModeTagsPoints) {
  TestPacket packet(0, 40, 0x38);
  packet.SetChannel(0, 0, 1000, 1);
  const auto decoder = MakeDecoder();
  std::vector<VelodynePoint> out(kMaxPointsPerPacket);
  auto result = decoder.Decode(packet.bytes, out);
  ASSERT_TRUE(result.has_value());
  EXPECT_EQ(result->return_mode, ReturnMode::kLast);
  EXPECT_EQ(out[0].return_tag, ReturnTag::kLast);
}

TEST(VelodyneDecoder, DualReturnKeepsAndTagsBothReturnsAndDropsCopies) {
  TestPacket single(500, 40);
  single.FillAll(2000, 10);
  single.SetChannel(0, 3, 0, 0);  // one laser without a return
  const auto duals_distinct = test::MakeDualFromSingle(single.bytes, 50, 0);
  const auto decoder = MakeDecoder();
  std::vector<VelodynePoint> out(kMaxPointsPerPacket);
  auto result = decoder.Decode(duals_distinct[0], out);
  ASSERT_TRUE(result.has_value());
  EXPECT_EQ(result->return_mode, ReturnMode::kDual);
  EXPECT_EQ(result->packet_duration_ns, 6u * 110592u);
  EXPECT_EQ(result->points, 6 * 64 - 2);  // both returns, minus the laser without any
  int last = 0, strongest = 0;
  for (std::size_t i = 0; i < result->points; ++i) {
    if (out[i].return_tag == ReturnTag::kDualLast) ++last;
    if (out[i].return_tag == ReturnTag::kDualStrongest) ++strongest;
  }
  EXPECT_EQ(last, strongest);
  // Both returns of one firing share time and azimuth; the strongest is 50 x 2 mm further.
  const VelodynePoint& a = out[0];
  const VelodynePoint& b = out[31];  // first record of the odd block (record 3 of block 0 missing)
  EXPECT_EQ(a.time_offset_ns, b.time_offset_ns);
  EXPECT_EQ(a.azimuth_cdeg, b.azimuth_cdeg);
  EXPECT_NEAR(b.range_m - a.range_m, 0.1, 1e-5);

  // Identical returns (the sensor saw one): the copy is dropped and counted, or kept if asked.
  const auto duals_same = test::MakeDualFromSingle(single.bytes, 0, 0);
  result = decoder.Decode(duals_same[0], out);
  ASSERT_TRUE(result.has_value());
  EXPECT_EQ(result->points, 6 * 32 - 1);
  EXPECT_EQ(result->dual_duplicates, 6 * 32 - 1);
  DecoderConfig keep;
  keep.drop_duplicate_dual_returns = false;
  result = MakeDecoder(keep).Decode(duals_same[0], out);
  ASSERT_TRUE(result.has_value());
  EXPECT_EQ(result->points, 6 * 64 - 2);
}

TEST(VelodyneDecoder, RangeLimitsAreAppliedAndCounted) {
  TestPacket packet(0, 40);
  packet.SetChannel(0, 0, 200, 1);    // 0.4 m
  packet.SetChannel(0, 1, 1000, 1);   // 2 m
  packet.SetChannel(0, 2, 60000, 1);  // 120 m
  DecoderConfig config;
  config.min_range_m = 1.0;
  config.max_range_m = 100.0;
  std::vector<VelodynePoint> out(kMaxPointsPerPacket);
  auto result = MakeDecoder(config).Decode(packet.bytes, out);
  ASSERT_TRUE(result.has_value());
  EXPECT_EQ(result->points, 1);
  EXPECT_EQ(result->out_of_range, 2);
  EXPECT_NEAR(out[0].range_m, 2.0, 1e-6);
}

TEST(VelodyneDecoder, MalformedPacketsAreRejectedWithAReason) {
  const auto decoder = MakeDecoder();
  std::vector<VelodynePoint> out(kMaxPointsPerPacket);
  TestPacket good(0, 40);
  ASSERT_TRUE(decoder.Decode(good.bytes, out).has_value());

  auto expect_malformed = [&](std::span<const std::uint8_t> bytes, const char* why) {
    auto r = decoder.Decode(bytes, out);
    ASSERT_FALSE(r.has_value()) << why;
    EXPECT_EQ(r.error().code, Errc::kMalformed) << why;
    EXPECT_STRNE(r.error().detail, "") << why;
  };
  expect_malformed(std::span<const std::uint8_t>(good.bytes).first(1205), "short");
  TestPacket bad_flag = good;
  bad_flag.bytes[500] = 0x00;
  expect_malformed(bad_flag.bytes, "block flag");
  TestPacket bad_azimuth = good;
  bad_azimuth.SetAzimuth(7, 36000);
  expect_malformed(bad_azimuth.bytes, "azimuth");
  TestPacket bad_mode = good;
  bad_mode.bytes[1204] = 0x40;
  expect_malformed(bad_mode.bytes, "return mode");
  TestPacket bad_time = good;
  bad_time.SetTimestamp(3'600'000'000u);
  expect_malformed(bad_time.bytes, "timestamp");
  TestPacket bad_dual(0, 40, 0x39);
  expect_malformed(bad_dual.bytes, "dual pair azimuths differ");

  std::vector<VelodynePoint> small(10);
  auto r = decoder.Decode(good.bytes, small);
  ASSERT_FALSE(r.has_value());
  EXPECT_EQ(r.error().code, Errc::kInvalidArgument);
}

TEST(VelodyneDecoder, ImplausibleAzimuthStepDisablesInterpolation) {
  TestPacket packet(0, 40);
  packet.SetAzimuth(5, 9000);  // a 90-degree jump between blocks 4 and 5
  packet.FillAll(1000, 1);
  std::vector<VelodynePoint> out(kMaxPointsPerPacket);
  auto result = MakeDecoder().Decode(packet.bytes, out);
  ASSERT_TRUE(result.has_value());
  const VelodynePoint* p = FindPoint(out, 0, 4 * 110592 + 55296);
  ASSERT_NE(p, nullptr);
  EXPECT_EQ(p->azimuth_cdeg, 160);  // block 4's own azimuth, not smeared towards 90 degrees
}

TEST(VelodyneDecoder, ModelFromPacketSpacing) {
  SensorModel model{};
  ASSERT_TRUE(ModelFromPacketSpacing(1327, ReturnMode::kStrongest, model));
  EXPECT_EQ(model, SensorModel::kVlp16);
  ASSERT_TRUE(ModelFromPacketSpacing(553, ReturnMode::kStrongest, model));
  EXPECT_EQ(model, SensorModel::kHdl32e);
  ASSERT_TRUE(ModelFromPacketSpacing(664, ReturnMode::kDual, model));
  EXPECT_EQ(model, SensorModel::kVlp16);
  EXPECT_FALSE(ModelFromPacketSpacing(2654, ReturnMode::kStrongest, model));  // a lost packet
}

TEST(VelodyneDecoder, DecodingAllocatesNothingPerPacket) {
  const auto decoder = MakeDecoder();
  std::vector<VelodynePoint> out(kMaxPointsPerPacket);
  std::vector<TestPacket> packets;
  for (int i = 0; i < 64; ++i) {
    TestPacket p(static_cast<std::uint32_t>(i * 480), 40, i % 3 == 0 ? 0x38 : 0x37);
    p.FillAll(static_cast<std::uint16_t>(1000 + i), 3);
    packets.push_back(p);
  }
  const auto dual = test::MakeDualFromSingle(packets[1].bytes, 7, 0);
  std::uint64_t points = 0;
  test::AllocationScope scope;
  for (int round = 0; round < 20; ++round) {
    for (const auto& p : packets) points += decoder.Decode(p.bytes, out).value().points;
    points += decoder.Decode(dual[0], out).value().points;
    points += DecodePositionPacket(std::span<const std::uint8_t>(packets[0].bytes).first(512)).has_value();
  }
  EXPECT_EQ(scope.allocations(), 0u);
  test::DoNotOptimize(points);
  EXPECT_GT(points, 0u);
}

std::array<std::uint8_t, 512> MakePositionPacket(std::uint32_t toh_us, std::uint8_t pps, const std::string& nmea) {
  std::array<std::uint8_t, 512> bytes{};
  bytes[187] = 40;
  bytes[188] = 38;
  for (int i = 0; i < 4; ++i) bytes[198 + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(toh_us >> (8 * i));
  bytes[202] = pps;
  std::memcpy(bytes.data() + 206, nmea.data(), nmea.size());
  return bytes;
}

std::string WithChecksum(const std::string& body) {
  unsigned x = 0;
  for (char c : body) x ^= static_cast<unsigned char>(c);
  char sum[8];
  std::snprintf(sum, sizeof(sum), "*%02X", x);
  return "$" + body + sum;
}

TEST(VelodynePositionPacket, DecodesTimePpsAndGprmc) {
  const std::string nmea = WithChecksum("GPRMC,081802.00,A,3649.7478558,N,00224.4542928,W,0.0,0.0,210116,,,A");
  const auto bytes = MakePositionPacket(1'082'000'000u, 2, nmea + "\r\n");
  auto packet = DecodePositionPacket(bytes);
  ASSERT_TRUE(packet.has_value());
  EXPECT_EQ(packet->device_time_us, 1'082'000'000u);
  EXPECT_EQ(packet->pps, PpsStatus::kLocked);
  EXPECT_EQ(packet->temperature_top_c, 40);
  EXPECT_EQ(packet->nmea_sentence().substr(0, 6), "$GPRMC");
  EXPECT_EQ(packet->fix.kind, NmeaFix::Kind::kRmc);
  EXPECT_TRUE(packet->fix.checksum_ok);
  EXPECT_TRUE(packet->fix.valid);
  EXPECT_EQ(packet->fix.utc_hour, 8);
  EXPECT_EQ(packet->fix.utc_minute, 18);
  EXPECT_NEAR(packet->fix.utc_second, 2.0, 1e-9);
  EXPECT_EQ(packet->fix.day, 21);
  EXPECT_EQ(packet->fix.month, 1);
  EXPECT_EQ(packet->fix.year, 2016);
}

TEST(VelodynePositionPacket, EmptyOrBrokenNmeaIsNotAnError) {
  auto packet = DecodePositionPacket(MakePositionPacket(5, 0, ""));
  ASSERT_TRUE(packet.has_value());
  EXPECT_EQ(packet->fix.kind, NmeaFix::Kind::kNone);
  EXPECT_EQ(packet->pps, PpsStatus::kAbsent);
  packet = DecodePositionPacket(MakePositionPacket(5, 1, "$GPRMC,0818"));
  ASSERT_TRUE(packet.has_value());
  EXPECT_EQ(packet->fix.kind, NmeaFix::Kind::kRmc);
  EXPECT_FALSE(packet->fix.valid);
  EXPECT_FALSE(packet->fix.checksum_ok);
  EXPECT_EQ(packet->fix.day, -1);
  const auto wrong_sum = WithChecksum("GPRMC,081802,A,,,,,,,210116,,") + "0";
  auto fix = ParseNmea(std::string(wrong_sum).replace(wrong_sum.size() - 3, 2, "00"));
  EXPECT_FALSE(fix.checksum_ok);
  EXPECT_EQ(ParseNmea("$GPGGA,1,2,3").kind, NmeaFix::Kind::kOther);
}

TEST(VelodynePositionPacket, RejectsWrongSizeTimeAndPps) {
  auto bytes = MakePositionPacket(5, 2, "");
  EXPECT_FALSE(DecodePositionPacket(std::span<const std::uint8_t>(bytes).first(511)).has_value());
  auto bad_pps = MakePositionPacket(5, 4, "");
  EXPECT_EQ(DecodePositionPacket(bad_pps).error().code, Errc::kMalformed);
  auto bad_time = MakePositionPacket(3'600'000'000u, 2, "");
  EXPECT_EQ(DecodePositionPacket(bad_time).error().code, Errc::kMalformed);
  // A sentence filling all 128 bytes without a terminator is cut at 128, not read past.
  std::array<std::uint8_t, 512> full = MakePositionPacket(5, 2, std::string(128, 'A'));
  for (std::size_t i = 334; i < 512; ++i) full[i] = 'B';
  auto packet = DecodePositionPacket(full);
  ASSERT_TRUE(packet.has_value());
  EXPECT_EQ(packet->nmea_length, 128);
}

}  // namespace
}  // namespace msgraphs::drivers::velodyne
