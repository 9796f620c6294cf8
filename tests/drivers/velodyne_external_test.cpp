// SPDX-License-Identifier: MIT
// The drivers against real sensor captures (../shared/data/pcap, provenance in SOURCES.md):
// raw test vectors, packet and rotation counts, position packets, the product-id 0x21 VLP-16,
// HDL-32E captures, and a dual-return recording built from a single-return one.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "msgraphs/drivers/pcap/pcap_writer.hpp"
#include "msgraphs/drivers/velodyne/data_packet_decoder.hpp"
#include "msgraphs/drivers/velodyne/position_packet.hpp"
#include "msgraphs/drivers/velodyne/scan_assembler.hpp"
#include "test_data.hpp"
#include "velodyne_capture.hpp"
#include "velodyne_test_packets.hpp"

namespace msgraphs::drivers::velodyne {
namespace {

std::vector<std::vector<std::uint8_t>> SplitRawPackets(const std::vector<std::uint8_t>& bytes) {
  std::vector<std::vector<std::uint8_t>> packets;
  for (std::size_t o = 0; o + kDataPacketBytes <= bytes.size(); o += kDataPacketBytes) {
    packets.emplace_back(bytes.begin() + static_cast<std::ptrdiff_t>(o),
                         bytes.begin() + static_cast<std::ptrdiff_t>(o + kDataPacketBytes));
  }
  return packets;
}

int CountWraps(const std::vector<std::vector<std::uint8_t>>& packets) {
  int wraps = 0;
  int previous = -1;
  for (const auto& p : packets) {
    for (int b = 0; b < kBlocksPerPacket; ++b) {
      const int az = ReadU16Le(p.data() + b * 100 + 2);
      if (previous >= 0 && az < previous) ++wraps;
      previous = az;
    }
  }
  return wraps;
}

struct DecodeSummary {
  std::size_t packets = 0, errors = 0, points = 0, scans = 0;
};

DecodeSummary DecodeAll(const std::vector<std::vector<std::uint8_t>>& packets, SensorModel model,
                        const std::vector<UnixTime>* times = nullptr) {
  DecoderConfig config;
  config.model = model;
  const auto decoder = DataPacketDecoder::Create(config).value();
  auto assembler = ScanAssembler::Create({}).value();
  std::vector<VelodynePoint> out(kMaxPointsPerPacket);
  DecodeSummary s;
  for (std::size_t i = 0; i < packets.size(); ++i) {
    auto r = decoder.Decode(packets[i], out);
    ++s.packets;
    if (!r) {
      ++s.errors;
      continue;
    }
    s.points += r->points;
    const UnixTime t = times != nullptr ? (*times)[i]
                                        : UnixTime::FromNanoseconds(static_cast<std::int64_t>(i) * r->packet_duration_ns);
    if (assembler.AddPacket(t, *r, std::span(out).first(r->points))) ++s.scans;
  }
  return s;
}

std::vector<std::vector<std::uint8_t>> Payloads(const std::vector<test::CapturedPayload>& v) {
  std::vector<std::vector<std::uint8_t>> out;
  for (const auto& p : v) out.push_back(p.bytes);
  return out;
}

TEST(VelodyneCaptures, EinrideRawRecordingVectorsAndRotations) {
  std::filesystem::path path;
  MSGRAPHS_REQUIRE_DATA("pcap/einride_vlp16_recording_1000pkts.bin", path);
  const auto packets = SplitRawPackets(test::ReadFileBytes(path.c_str()));
  ASSERT_EQ(packets.size(), 1000u);
  const auto& p0 = packets[0];
  EXPECT_EQ(ReadU16Le(p0.data() + 2), 10342);
  EXPECT_EQ(ReadU32Le(p0.data() + 1200), 2'666'163'099u);
  EXPECT_EQ(p0[1204], 0x37);
  EXPECT_EQ(p0[1205], 0x22);

  const auto decoder = DataPacketDecoder::Create({}).value();
  std::vector<VelodynePoint> out(kMaxPointsPerPacket);
  auto r = decoder.Decode(p0, out).value();
  // Firing 0 of block 0: laser 1 = 767 x 2 mm (refl 3), laser 3 = 784 (75), laser 5 = 684 (57).
  auto find = [&](int laser) -> const VelodynePoint* {
    for (std::size_t i = 0; i < r.points; ++i) {
      if (out[i].laser_id == laser && out[i].time_offset_ns < 55296) return &out[i];
    }
    return nullptr;
  };
  ASSERT_NE(find(1), nullptr);
  EXPECT_NEAR(find(1)->range_m, 767 * 0.002, 1e-6);
  EXPECT_EQ(find(1)->intensity, 3);
  EXPECT_NEAR(find(3)->range_m, 784 * 0.002, 1e-6);
  EXPECT_EQ(find(3)->intensity, 75);
  EXPECT_EQ(find(5)->intensity, 57);

  // Device times are 1327/1328 us apart: the VLP-16 timing, whatever byte 1205 says.
  SensorModel model{};
  ASSERT_TRUE(ModelFromPacketSpacing(ReadU32Le(packets[1].data() + 1200) - ReadU32Le(p0.data() + 1200),
                                     ReturnMode::kStrongest, model));
  EXPECT_EQ(model, SensorModel::kVlp16);

  EXPECT_EQ(CountWraps(packets), 13);
  const auto summary = DecodeAll(packets, SensorModel::kVlp16);
  EXPECT_EQ(summary.errors, 0u);
  EXPECT_EQ(summary.scans, 13u);
  // 52.9 % of channel records carry a return.
  EXPECT_NEAR(static_cast<double>(summary.points) / (1000.0 * 384.0), 0.529, 0.005);
}

TEST(VelodyneCaptures, MrptVlp16WithGpsPositionPackets) {
  std::filesystem::path path;
  MSGRAPHS_REQUIRE_DATA("pcap/mrpt_sample_velodyne_vlp16_gps.pcap", path);
  const auto capture = test::LoadCapture(path.string());
  ASSERT_TRUE(capture.read_to_end);
  EXPECT_EQ(capture.data.size(), 293u);
  EXPECT_EQ(capture.position.size(), 57u);
  for (const auto& p : capture.data) EXPECT_EQ(p.port, kDefaultDataPort);
  for (const auto& p : capture.position) EXPECT_EQ(p.port, kDefaultPositionPort);

  const auto& p0 = capture.data[0].bytes;
  EXPECT_EQ(ReadU16Le(p0.data() + 2), 11888);
  EXPECT_EQ(ReadU32Le(p0.data() + 1200), 1'082'340'595u);
  std::vector<VelodynePoint> out(kMaxPointsPerPacket);
  auto r = DataPacketDecoder::Create({}).value().Decode(p0, out).value();
  ASSERT_GE(r.points, 2);
  EXPECT_EQ(out[0].laser_id, 13);
  EXPECT_NEAR(out[0].range_m, 1.438, 1e-6);
  EXPECT_EQ(out[0].intensity, 17);
  EXPECT_EQ(out[1].laser_id, 15);
  EXPECT_NEAR(out[1].range_m, 1.464, 1e-6);
  EXPECT_EQ(out[1].intensity, 41);

  auto position = DecodePositionPacket(capture.position[0].bytes).value();
  EXPECT_EQ(position.pps, PpsStatus::kLocked);
  EXPECT_EQ(position.nmea_sentence().substr(0, 17), "$GPRMC,081802.00,");
  EXPECT_EQ(position.fix.kind, NmeaFix::Kind::kRmc);
  EXPECT_TRUE(position.fix.valid);
  EXPECT_TRUE(position.fix.checksum_ok);
  EXPECT_EQ(position.fix.year, 2016);
  EXPECT_EQ(position.fix.month, 1);
  EXPECT_EQ(position.fix.day, 21);
  // Position packets every ~8 ms of device time (median spacing 7962 us).
  std::vector<std::uint32_t> spacing;
  for (std::size_t i = 1; i < capture.position.size(); ++i) {
    spacing.push_back(DecodePositionPacket(capture.position[i].bytes).value().device_time_us -
                      DecodePositionPacket(capture.position[i - 1].bytes).value().device_time_us);
  }
  std::nth_element(spacing.begin(), spacing.begin() + static_cast<std::ptrdiff_t>(spacing.size() / 2), spacing.end());
  EXPECT_NEAR(static_cast<double>(spacing[spacing.size() / 2]), 7962.0, 100.0);
  // With PPS locked, device time past the hour matches host time to 0.37 s.
  const double host_in_hour = std::fmod(capture.data[0].time.seconds_since_epoch(), 3600.0);
  EXPECT_NEAR(std::fabs(host_in_hour - ReadU32Le(p0.data() + 1200) * 1e-6), 0.37, 0.05);

  const auto summary = DecodeAll(Payloads(capture.data), SensorModel::kVlp16);
  EXPECT_EQ(summary.errors, 0u);
  EXPECT_EQ(CountWraps(Payloads(capture.data)), static_cast<int>(summary.scans));
  EXPECT_GE(summary.scans, 3u);
}

TEST(VelodyneCaptures, LidarUtilsVlp16ExampleFirstFiring) {
  std::filesystem::path path;
  MSGRAPHS_REQUIRE_DATA("pcap/lidarutils_velodyne_example_vlp16.pcap", path);
  const auto capture = test::LoadCapture(path.string());
  EXPECT_EQ(capture.data.size(), 84u);
  EXPECT_EQ(capture.position.size(), 0u);
  const auto& p0 = capture.data[0].bytes;
  EXPECT_EQ(ReadU16Le(p0.data() + 2), 23424);
  std::vector<VelodynePoint> out(kMaxPointsPerPacket);
  auto r = DataPacketDecoder::Create({}).value().Decode(p0, out).value();
  ASSERT_GE(r.points, 16);
  EXPECT_EQ(out[0].laser_id, 0);
  EXPECT_NEAR(out[0].range_m, 2392 * 0.002, 1e-6);
  EXPECT_EQ(out[0].intensity, 48);
  EXPECT_NEAR(out[1].range_m, 2301 * 0.002, 1e-6);
  EXPECT_EQ(out[1].intensity, 23);
  EXPECT_EQ(out[15].laser_id, 15);
  EXPECT_NEAR(out[15].range_m, 2418 * 0.002, 1e-6);
  EXPECT_EQ(out[15].intensity, 66);
  EXPECT_EQ(DecodeAll(Payloads(capture.data), SensorModel::kVlp16).errors, 0u);
}

TEST(VelodyneCaptures, Vlp16ReportingHdl32ProductIdIsTimedAsVlp16) {
  std::filesystem::path path;
  MSGRAPHS_REQUIRE_DATA("pcap/lidarutils_velodyne_vlp16_pid0x21.pcap", path);
  const auto capture = test::LoadCapture(path.string());
  EXPECT_EQ(capture.data.size(), 84u);
  EXPECT_EQ(capture.position.size(), 16u);
  EXPECT_EQ(capture.data[0].bytes[1205], 0x21);
  SensorModel model{};
  ASSERT_TRUE(ModelFromPacketSpacing(ReadU32Le(capture.data[1].bytes.data() + 1200) -
                                         ReadU32Le(capture.data[0].bytes.data() + 1200),
                                     ReturnMode::kStrongest, model));
  EXPECT_EQ(model, SensorModel::kVlp16);
  auto position = DecodePositionPacket(capture.position[0].bytes).value();
  EXPECT_EQ(position.pps, PpsStatus::kAbsent);
  EXPECT_EQ(position.nmea_length, 0);
  EXPECT_EQ(position.fix.kind, NmeaFix::Kind::kNone);
  const auto summary = DecodeAll(Payloads(capture.data), model);
  EXPECT_EQ(summary.errors, 0u);
  // Outdoor capture: returns out to ~110 m decode in range.
  DecoderConfig config;
  const auto decoder = DataPacketDecoder::Create(config).value();
  std::vector<VelodynePoint> out(kMaxPointsPerPacket);
  float max_range = 0;
  for (const auto& p : capture.data) {
    auto r = decoder.Decode(p.bytes, out).value();
    for (std::size_t i = 0; i < r.points; ++i) max_range = std::max(max_range, out[i].range_m);
  }
  EXPECT_NEAR(max_range, 109.9, 0.2);
}

struct Hdl32Case {
  const char* file;
  std::size_t data, position;
};

class Hdl32Captures : public ::testing::TestWithParam<Hdl32Case> {};

TEST_P(Hdl32Captures, DecodeWithHdl32Timing) {
  std::filesystem::path path;
  MSGRAPHS_REQUIRE_DATA(std::string("pcap/") + GetParam().file, path);
  const auto capture = test::LoadCapture(path.string());
  ASSERT_TRUE(capture.read_to_end);
  EXPECT_EQ(capture.data.size(), GetParam().data);
  EXPECT_EQ(capture.position.size(), GetParam().position);
  SensorModel model{};
  ASSERT_TRUE(ModelFromPacketSpacing(ReadU32Le(capture.data[1].bytes.data() + 1200) -
                                         ReadU32Le(capture.data[0].bytes.data() + 1200),
                                     ReturnMode::kStrongest, model));
  EXPECT_EQ(model, SensorModel::kHdl32e);
  std::vector<UnixTime> times;
  for (const auto& p : capture.data) times.push_back(p.time);
  const auto summary = DecodeAll(Payloads(capture.data), SensorModel::kHdl32e, &times);
  EXPECT_EQ(summary.errors, 0u);
  EXPECT_EQ(static_cast<int>(summary.scans), CountWraps(Payloads(capture.data)));
  EXPECT_GT(summary.points, GetParam().data * 100);
}

INSTANTIATE_TEST_SUITE_P(Files, Hdl32Captures,
                         ::testing::Values(Hdl32Case{"lidarutils_velodyne_vlp32_actually_hdl32e.pcap", 91, 9},
                                           Hdl32Case{"lidarutils_hdl32_example.pcap", 876, 100},
                                           Hdl32Case{"mrpt_sample_velodyne_hdl32.pcap", 500, 0}));

TEST(VelodyneCaptures, Hdl32PositionPacketCarriesGprmc) {
  std::filesystem::path path;
  MSGRAPHS_REQUIRE_DATA("pcap/lidarutils_velodyne_vlp32_actually_hdl32e.pcap", path);
  const auto capture = test::LoadCapture(path.string());
  ASSERT_FALSE(capture.position.empty());
  auto position = DecodePositionPacket(capture.position[0].bytes).value();
  EXPECT_EQ(position.nmea_sentence().substr(0, 14), "$GPRMC,214616,");
  EXPECT_TRUE(position.fix.valid);
  EXPECT_EQ(position.fix.year, 2012);
}

// No public dual-return VLP-16 capture exists: build one from the einride recording the way a
// dual-mode sensor sends it, write it as a pcap, read it back and decode it.
TEST(VelodyneCaptures, DualReturnFileBuiltFromSingleReturnDecodesConsistently) {
  std::filesystem::path path;
  MSGRAPHS_REQUIRE_DATA("pcap/einride_vlp16_recording_1000pkts.bin", path);
  const auto singles = SplitRawPackets(test::ReadFileBytes(path.c_str()));
  const std::string pcap_path = (std::filesystem::temp_directory_path() /
                                 ("msgraphs_dual_" + std::to_string(::getpid()) + ".pcap")).string();
  {
    auto writer = pcap::PcapFileWriter::Create(pcap_path.c_str(), pcap::TimestampPrecision::kNanoseconds).value();
    UnixTime t = UnixTime::FromSeconds(1700000000.0);
    for (const auto& single : singles) {
      std::array<std::uint8_t, 1206> bytes{};
      std::copy(single.begin(), single.end(), bytes.begin());
      const std::uint32_t toh = ReadU32Le(single.data() + 1200);
      // The strongest return is 10 cm beyond the last where one exists (distinct returns).
      const auto duals = test::MakeDualFromSingle(bytes, 50, toh + 664);
      for (const auto& d : duals) {
        ASSERT_TRUE(writer.WriteUdp(t, {0xC0A801C9, 2368}, {0xFFFFFFFF, 2368}, d));
        t += Duration::FromMicroseconds(664);
      }
    }
    ASSERT_TRUE(writer.Close());
  }
  const auto capture = test::LoadCapture(pcap_path);
  std::remove(pcap_path.c_str());
  ASSERT_EQ(capture.data.size(), 2 * singles.size());
  SensorModel model{};
  ASSERT_TRUE(ModelFromPacketSpacing(664, ReturnMode::kDual, model));
  EXPECT_EQ(model, SensorModel::kVlp16);

  const auto decoder = DataPacketDecoder::Create({}).value();
  std::vector<VelodynePoint> single_out(kMaxPointsPerPacket), dual_out(kMaxPointsPerPacket);
  std::size_t single_points = 0, last_points = 0, strongest_points = 0;
  int max_azimuth_diff = 0;
  for (std::size_t i = 0; i < singles.size(); ++i) {
    auto s = decoder.Decode(singles[i], single_out).value();
    single_points += s.points;
    std::size_t k = 0;  // walks the single packet's points in order
    for (int h = 0; h < 2; ++h) {
      auto d = decoder.Decode(capture.data[2 * i + static_cast<std::size_t>(h)].bytes, dual_out).value();
      ASSERT_EQ(d.return_mode, ReturnMode::kDual);
      for (std::size_t j = 0; j < d.points; ++j) {
        const VelodynePoint& p = dual_out[j];
        if (p.return_tag == ReturnTag::kDualStrongest) {
          ++strongest_points;
          continue;
        }
        ++last_points;
        ASSERT_LT(k, s.points);
        const VelodynePoint& q = single_out[k++];
        ASSERT_EQ(p.laser_id, q.laser_id);
        ASSERT_FLOAT_EQ(p.range_m, q.range_m);
        // Same firing, same azimuth, except the last firing of each half, which extrapolates
        // with the previous step instead of the next block's azimuth.
        max_azimuth_diff = std::max(max_azimuth_diff, std::abs(int{p.azimuth_cdeg} - int{q.azimuth_cdeg}) % 35990);
      }
    }
    EXPECT_EQ(k, s.points);
  }
  EXPECT_EQ(last_points, single_points);
  EXPECT_EQ(strongest_points, single_points);
  EXPECT_LE(max_azimuth_diff, 3);
}

}  // namespace
}  // namespace msgraphs::drivers::velodyne
