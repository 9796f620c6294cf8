// SPDX-License-Identifier: MIT
// Scan assembly (rotation cuts, per-point time, overflow, gaps) and device-clock mapping on a
// synthetic 600 RPM VLP-16 stream.
#include <gtest/gtest.h>

#include <vector>

#include "alloc_counter.hpp"
#include "msgraphs/drivers/velodyne/data_packet_decoder.hpp"
#include "msgraphs/drivers/velodyne/device_clock.hpp"
#include "msgraphs/drivers/velodyne/scan_assembler.hpp"
#include "velodyne_test_packets.hpp"

namespace msgraphs::drivers::velodyne {
namespace {

constexpr std::int64_t kPacketNs = 1327104;
// 36000 cdeg per 100 ms = 39.8 cdeg per block; use 40 with 75 packets of 12 blocks per turn.
constexpr std::uint32_t kStepCdeg = 40;
constexpr int kPacketsPerTurn = 75;

struct Stream {
  DataPacketDecoder decoder = DataPacketDecoder::Create({}).value();
  std::vector<VelodynePoint> points = std::vector<VelodynePoint>(kMaxPointsPerPacket);
  UnixTime t0 = UnixTime::FromSeconds(1700000000.0);

  // Feeds packets [first, first + count) starting at azimuth `start_cdeg`; returns scans.
  int Feed(ScanAssembler& assembler, int first, int count, std::uint32_t start_cdeg,
           std::vector<std::size_t>* sizes = nullptr, std::int64_t extra_gap_ns = 0) {
    int scans = 0;
    for (int k = first; k < first + count; ++k) {
      test::TestPacket p((start_cdeg + static_cast<std::uint32_t>(k) * 12 * kStepCdeg) % 36000, kStepCdeg);
      p.FillAll(1500, 9);
      const auto decoded = decoder.Decode(p.bytes, points).value();
      const UnixTime t = t0 + Duration::FromNanoseconds(k * kPacketNs + extra_gap_ns);
      if (assembler.AddPacket(t, decoded, std::span(points).first(decoded.points))) {
        ++scans;
        if (sizes != nullptr) sizes->push_back(assembler.completed().points.size());
      }
    }
    return scans;
  }
};

TEST(ScanAssembler, CutsOneScanPerRotationAtTheCutAzimuth) {
  ScanAssemblerConfig config;
  config.cut_azimuth_cdeg = 0;
  auto assembler = ScanAssembler::Create(config).value();
  Stream stream;
  std::vector<std::size_t> sizes;
  // Start half a turn in: the first scan is partial, then whole rotations.
  const int scans = stream.Feed(assembler, 0, 4 * kPacketsPerTurn + 10, 18000, &sizes);
  EXPECT_EQ(scans, 4);
  ASSERT_EQ(sizes.size(), 4u);
  EXPECT_NEAR(static_cast<double>(sizes[0]), 384.0 * kPacketsPerTurn / 2, 400);
  for (std::size_t i = 1; i < sizes.size(); ++i) EXPECT_EQ(sizes[i], 384u * kPacketsPerTurn) << i;
  EXPECT_EQ(assembler.stats().partial_scans, 1u);

  const Scan& scan = assembler.completed();
  EXPECT_TRUE(scan.complete);
  EXPECT_EQ(scan.sequence, 3u);
  // Every point lies after the cut, and time increases through the scan (single return).
  for (std::size_t i = 1; i < scan.points.size(); ++i) {
    ASSERT_GE(scan.points[i].time_offset_ns, scan.points[i - 1].time_offset_ns) << i;
  }
  const double span_s = (scan.end_time - scan.start_time).seconds();
  EXPECT_NEAR(span_s, 0.0995, 0.002);
  EXPECT_LT(scan.points[0].azimuth_cdeg, 100);
  EXPECT_GT(scan.points[scan.points.size() - 1].azimuth_cdeg, 35800);
}

TEST(ScanAssembler, CutInsideAPacketSplitsItsPoints) {
  ScanAssemblerConfig config;
  config.cut_azimuth_cdeg = 9010;  // not on a block boundary
  auto assembler = ScanAssembler::Create(config).value();
  Stream stream;
  std::vector<std::size_t> sizes;
  stream.Feed(assembler, 0, 3 * kPacketsPerTurn, 0, &sizes);
  ASSERT_GE(sizes.size(), 2u);
  EXPECT_EQ(sizes[1], 384u * kPacketsPerTurn);
  // The scan runs from the cut once round: the angle past the cut only grows.
  const Scan& scan = assembler.completed();
  std::uint32_t previous = 0;
  for (const auto& p : scan.points) {
    const std::uint32_t from_cut = (p.azimuth_cdeg + 36000u - 9010u) % 36000u;
    ASSERT_GE(from_cut, previous);
    previous = from_cut;
  }
  EXPECT_LT((scan.points[0].azimuth_cdeg + 36000u - 9010u) % 36000u, 40u);
  EXPECT_GT(previous, 36000u - 40u);
}

TEST(ScanAssembler, OverflowDropsAndCountsButStillDelivers) {
  ScanAssemblerConfig config;
  config.capacity_points = 10000;
  auto assembler = ScanAssembler::Create(config).value();
  Stream stream;
  std::vector<std::size_t> sizes;
  stream.Feed(assembler, 0, 2 * kPacketsPerTurn + 5, 0, &sizes);
  ASSERT_FALSE(sizes.empty());
  const Scan& scan = assembler.completed();
  EXPECT_EQ(scan.points.size(), 10000u);
  EXPECT_EQ(scan.dropped_points, 384u * kPacketsPerTurn - 10000u);
  EXPECT_GE(assembler.stats().dropped_points, scan.dropped_points);
  EXPECT_EQ(assembler.stats().peak_points, 10000u);
}

TEST(ScanAssembler, AnInputGapClosesThePartialScan) {
  auto assembler = ScanAssembler::Create({}).value();
  Stream stream;
  stream.Feed(assembler, 0, 20, 0);
  // One second of silence, then data resumes mid-rotation.
  const int scans = stream.Feed(assembler, 20, 5, 0, nullptr, 1'000'000'000);
  EXPECT_EQ(scans, 1);
  EXPECT_EQ(assembler.stats().timeouts, 1u);
  EXPECT_FALSE(assembler.completed().complete);
  EXPECT_EQ(assembler.completed().packets, 20u);
}

TEST(ScanAssembler, OlderPacketsAreDroppedAndCounted) {
  auto assembler = ScanAssembler::Create({}).value();
  Stream stream;
  stream.Feed(assembler, 10, 5, 0);
  stream.Feed(assembler, 0, 1, 0);  // from before the scan started
  EXPECT_EQ(assembler.stats().time_regressions, 1u);
  EXPECT_EQ(assembler.stats().dropped_regressed_points, 384u);
}

TEST(ScanAssembler, DualReturnsOfOneFiringStayInOneScan) {
  ScanAssemblerConfig config;
  config.cut_azimuth_cdeg = 200;  // inside the first dual packet's firings
  auto assembler = ScanAssembler::Create(config).value();
  Stream stream;
  DecoderConfig keep;
  keep.drop_duplicate_dual_returns = false;
  auto decoder = DataPacketDecoder::Create(keep).value();
  int delivered = 0;
  for (int k = 0; k < 2 * kPacketsPerTurn; ++k) {
    test::TestPacket single((static_cast<std::uint32_t>(k) * 480) % 36000, kStepCdeg);
    single.FillAll(1500, 9);
    const auto duals = test::MakeDualFromSingle(single.bytes, 10, 0);
    for (int h = 0; h < 2; ++h) {
      const auto decoded = decoder.Decode(duals[static_cast<std::size_t>(h)], stream.points).value();
      const UnixTime t = stream.t0 + Duration::FromNanoseconds(k * kPacketNs + h * kPacketNs / 2);
      if (assembler.AddPacket(t, decoded, std::span(stream.points).first(decoded.points))) ++delivered;
    }
  }
  ASSERT_GE(delivered, 2);
  const Scan& scan = assembler.completed();
  EXPECT_EQ(scan.points.size(), 2u * 384u * kPacketsPerTurn);
  std::size_t last = 0, strongest = 0;
  for (const auto& p : scan.points) (p.return_tag == ReturnTag::kDualLast ? last : strongest)++;
  EXPECT_EQ(last, strongest);
}

TEST(ScanAssembler, AssemblingAllocatesNothing) {
  auto assembler = ScanAssembler::Create({}).value();
  Stream stream;
  stream.Feed(assembler, 0, 10, 0);
  test::AllocationScope scope;
  const int scans = stream.Feed(assembler, 10, 3 * kPacketsPerTurn, 0);
  EXPECT_EQ(scope.allocations(), 0u);
  EXPECT_EQ(scans, 3);
}

TEST(ScanAssembler, RejectsBadConfig) {
  ScanAssemblerConfig config;
  config.cut_azimuth_cdeg = 36000;
  EXPECT_EQ(ScanAssembler::Create(config).error().code, Errc::kInvalidConfig);
  config = {};
  config.capacity_points = 0;
  EXPECT_FALSE(ScanAssembler::Create(config).has_value());
  config = {};
  config.max_scan_duration = Duration::FromSeconds(10.0);
  EXPECT_FALSE(ScanAssembler::Create(config).has_value());
}

TEST(DeviceClockSync, RemovesArrivalJitterAndKeepsDeviceSpacing) {
  DeviceClockSync sync;
  const std::int64_t host0 = 1'700'000'000'000'000'000;
  std::uint32_t device_us = 1'000'000'000;
  const std::int64_t latency_floor_ns = 150'000;
  std::int64_t max_error_ns = 0;
  for (int k = 0; k < 2000; ++k) {
    const std::int64_t true_first_firing = host0 + static_cast<std::int64_t>(k) * 1327104;
    const std::int64_t jitter = (k * 7919) % 400'000;  // 0..400 us of scheduling noise
    const UnixTime arrival = UnixTime::FromNanoseconds(true_first_firing + 1327104 + latency_floor_ns + jitter);
    const UnixTime mapped = sync.Map(arrival, device_us + static_cast<std::uint32_t>((k * 1327104LL) / 1000), 1327104);
    if (k > 100) {
      const std::int64_t error = mapped.nanoseconds_since_epoch() - (true_first_firing + latency_floor_ns);
      max_error_ns = std::max(max_error_ns, std::abs(error));
    }
  }
  // Raw arrivals jitter by 400 us; the envelope may rise 200 ppm x 1.3 ms per packet between
  // the (rare) fastest packets, so a few tens of microseconds remain.
  EXPECT_LT(max_error_ns, 30'000);
  EXPECT_EQ(sync.resets(), 0u);
}

TEST(DeviceClockSync, UnwrapsTheHour) {
  DeviceClockSync sync;
  const UnixTime t0 = UnixTime::FromSeconds(1700000000.0);
  const UnixTime a = sync.Map(t0, 3'599'999'000u, 0);
  const UnixTime b = sync.Map(t0 + Duration::FromMicroseconds(2000), 1000u, 0);  // past the hour
  EXPECT_EQ((b - a).nanoseconds(), 2'000'000);
  EXPECT_EQ(sync.hour_wraps(), 1u);
  // A late packet from before the wrap maps before it, without moving the hour back.
  const UnixTime late = sync.Map(t0 + Duration::FromMicroseconds(2500), 3'599'999'500u, 0);
  EXPECT_EQ((late - a).nanoseconds(), 500'000);
  const UnixTime c = sync.Map(t0 + Duration::FromMicroseconds(3000), 2000u, 0);
  EXPECT_EQ((c - a).nanoseconds(), 3'000'000);
}

TEST(DeviceClockSync, AClockJumpRestartsTheMapping) {
  DeviceClockSync sync;
  const UnixTime t0 = UnixTime::FromSeconds(1700000000.0);
  static_cast<void>(sync.Map(t0, 1'000'000u, 0));
  // The sensor's clock jumps by 10 s (PPS acquired): mapping follows the host again.
  const UnixTime mapped = sync.Map(t0 + Duration::FromMilliseconds(1), 11'001'000u, 0);
  EXPECT_EQ(sync.resets(), 1u);
  EXPECT_EQ(mapped, t0 + Duration::FromMilliseconds(1));
}

}  // namespace
}  // namespace msgraphs::drivers::velodyne
