// SPDX-License-Identifier: MIT
// Hardware-in-the-loop path on loopback: the real msgraphs_replay process sends a pcap over UDP
// to our UdpReceiver; decoding what arrives gives exactly the points of decoding the file
// directly, with zero loss at 1x. Flooding a slow receiver gives counted drops, not a crash.
// msgraphs_record turns the same traffic back into a pcap with the same payloads.
#include <gtest/gtest.h>

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "../drivers/velodyne_capture.hpp"
#include "alloc_counter.hpp"
#include "../drivers/velodyne_test_packets.hpp"
#include "msgraphs/drivers/pcap/pcap_writer.hpp"
#include "msgraphs/drivers/velodyne/data_packet_decoder.hpp"
#include "msgraphs/drivers/velodyne/scan_assembler.hpp"
#include "msgraphs/drivers/velodyne/velodyne_source.hpp"
#include "msgraphs/platform/clock.hpp"
#include "msgraphs/platform/udp_socket.hpp"
#include "test_data.hpp"
#include "tool_process.hpp"

namespace msgraphs {
namespace {

using test::Exited;
using test::Receiver;
using test::Spawn;
using test::Temp;
using test::Wait;


std::vector<drivers::velodyne::VelodynePoint> DecodeAll(const std::vector<std::vector<std::uint8_t>>& payloads) {
  const auto decoder = drivers::velodyne::DataPacketDecoder::Create({}).value();
  std::vector<drivers::velodyne::VelodynePoint> all, out(drivers::velodyne::kMaxPointsPerPacket);
  for (const auto& p : payloads) {
    auto r = decoder.Decode(p, out).value();
    all.insert(all.end(), out.begin(), out.begin() + r.points);
  }
  return all;
}

TEST(ReplayLoopback, ReceivedPointsEqualTheFileAtRecordedPaceWithoutLoss) {
  std::filesystem::path path;
  MSGRAPHS_REQUIRE_DATA("pcap/mrpt_sample_velodyne_vlp16_gps.pcap", path);
  const auto capture = test::LoadCapture(path.string());
  ASSERT_EQ(capture.data.size(), 293u);

  auto data = Receiver(1206);
  auto position = Receiver(512);
  const pid_t replay = Spawn({MSGRAPHS_REPLAY_TOOL, "--pcap", path.string(), "--to", "127.0.0.1", "--data-port",
                              std::to_string(data.bound_port()), "--position-port",
                              std::to_string(position.bound_port()), "--speed", "1"});
  std::vector<std::vector<std::uint8_t>> got_data;
  std::size_t got_position = 0;
  int code = -1;
  SteadyTime quiet_until = platform::SteadyNow() + Duration::FromSeconds(10.0);
  while (platform::SteadyNow() < quiet_until) {
    const int fds[2] = {data.fd(), position.fd()};
    const std::uint32_t ready = platform::WaitReadable(fds, platform::SteadyNow() + Duration::FromMilliseconds(50)).value();
    if ((ready & 1u) != 0) {
      const std::size_t n = data.Receive(platform::SteadyNow()).value();
      for (std::size_t i = 0; i < n; ++i) got_data.emplace_back(data.datagram(i).payload.begin(), data.datagram(i).payload.end());
    }
    if ((ready & 2u) != 0) got_position += position.Receive(platform::SteadyNow()).value();
    if (code < 0 && Exited(replay, code)) quiet_until = platform::SteadyNow() + Duration::FromMilliseconds(200);
  }
  ASSERT_EQ(code, 0);
  EXPECT_EQ(got_data.size(), 293u);
  EXPECT_EQ(got_position, 57u);
  EXPECT_EQ(data.stats().kernel_drops + position.stats().kernel_drops, 0u);

  std::vector<std::vector<std::uint8_t>> file_data;
  for (const auto& p : capture.data) file_data.push_back(p.bytes);
  const auto expected = DecodeAll(file_data);
  const auto received = DecodeAll(got_data);
  ASSERT_EQ(received.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    ASSERT_EQ(std::memcmp(&received[i], &expected[i], sizeof(expected[i])), 0) << "point " << i;
  }
}

TEST(ReplayLoopback, RecorderWritesWhatTheReplaySends) {
  std::filesystem::path path;
  MSGRAPHS_REQUIRE_DATA("pcap/lidarutils_velodyne_vlp16_pid0x21.pcap", path);
  const auto original = test::LoadCapture(path.string());
  const std::string out = Temp("recorded.pcap");
  // Free ports for the recorder: take ephemeral ones, release them, hand them over.
  std::uint16_t ports[2];
  {
    auto a = Receiver(0);
    auto b = Receiver(0);
    ports[0] = a.bound_port();
    ports[1] = b.bound_port();
  }
  const pid_t record = Spawn({MSGRAPHS_RECORD_TOOL, "--out", out, "--bind", "127.0.0.1", "--data-port",
                              std::to_string(ports[0]), "--position-port", std::to_string(ports[1]),
                              "--duration-s", "20", "--packets", std::to_string(original.data.size())});
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // let it bind
  const pid_t replay = Spawn({MSGRAPHS_REPLAY_TOOL, "--pcap", path.string(), "--to", "127.0.0.1", "--data-port",
                              std::to_string(ports[0]), "--position-port", std::to_string(ports[1]), "--speed", "2"});
  ASSERT_EQ(Wait(replay), 0);
  ASSERT_EQ(Wait(record), 0);
  const auto recorded = test::LoadCapture(out);
  std::remove(out.c_str());
  ASSERT_TRUE(recorded.read_to_end);
  ASSERT_EQ(recorded.data.size(), original.data.size());
  for (std::size_t i = 0; i < original.data.size(); ++i) {
    EXPECT_EQ(recorded.data[i].bytes, original.data[i].bytes) << i;
    if (i > 0) {
      EXPECT_GE(recorded.data[i].time, recorded.data[i - 1].time);
    }
  }
  EXPECT_GE(recorded.position.size(), original.position.size() - 1);  // the last may follow the last data packet
}


TEST(ReplayLoopback, VelodyneSourceAssemblesTheSameScansAsTheFile) {
  namespace vel = drivers::velodyne;
  std::filesystem::path path;
  MSGRAPHS_REQUIRE_DATA("pcap/mrpt_sample_velodyne_vlp16_gps.pcap", path);
  const auto capture = test::LoadCapture(path.string());

  // Scans from the file directly.
  std::vector<std::vector<vel::VelodynePoint>> expected;
  {
    const auto decoder = vel::DataPacketDecoder::Create({}).value();
    auto assembler = vel::ScanAssembler::Create({}).value();
    std::vector<vel::VelodynePoint> out(vel::kMaxPointsPerPacket);
    for (const auto& p : capture.data) {
      auto r = decoder.Decode(p.bytes, out).value();
      if (assembler.AddPacket(p.time, r, std::span(out).first(r.points))) {
        expected.emplace_back(assembler.completed().points.begin(), assembler.completed().points.end());
      }
    }
  }
  ASSERT_GE(expected.size(), 3u);

  vel::VelodyneSourceConfig config;
  config.bind_address = kIpv4Loopback;
  config.data_port = 0;
  config.position_port = 0;
  auto source = vel::VelodyneSource::Open(config).value();
  const pid_t replay = Spawn({MSGRAPHS_REPLAY_TOOL, "--pcap", path.string(), "--to", "127.0.0.1", "--data-port",
                              std::to_string(source.data_port()), "--position-port",
                              std::to_string(source.position_port())});
  std::vector<std::vector<vel::VelodynePoint>> live;
  std::vector<double> spans_s;
  int code = -1;
  SteadyTime quiet_until = platform::SteadyNow() + Duration::FromSeconds(10.0);
  // Receiving, decoding and assembling live packets allocates nothing: every buffer was
  // allocated at Open (velodyne_source.hpp). Only Poll is counted, not the test's own copies.
  std::uint64_t poll_allocations = 0;
  while (platform::SteadyNow() < quiet_until) {
    bool got = false;
    {
      test::AllocationScope scope;
      got = source.Poll(platform::SteadyNow() + Duration::FromMilliseconds(50)).value();
      poll_allocations += scope.allocations();
    }
    if (got) {
      live.emplace_back(source.scan().points.begin(), source.scan().points.end());
      spans_s.push_back((source.scan().end_time - source.scan().start_time).seconds());
    }
    if (code < 0 && Exited(replay, code)) quiet_until = platform::SteadyNow() + Duration::FromMilliseconds(200);
  }
  ASSERT_EQ(code, 0);
  EXPECT_EQ(poll_allocations, 0u);
  const auto stats = source.stats();
  EXPECT_EQ(stats.data_packets, 293u);
  EXPECT_EQ(stats.malformed_data, 0u);
  EXPECT_EQ(stats.position_packets, 57u);
  EXPECT_EQ(stats.data_udp.kernel_drops, 0u);
  ASSERT_TRUE(source.position().has_value());
  EXPECT_EQ(source.position()->pps, vel::PpsStatus::kLocked);

  // Same scans, same points; only the time base differs (device clock mapped to arrival).
  ASSERT_EQ(live.size(), expected.size());
  for (std::size_t s = 0; s < live.size(); ++s) {
    ASSERT_EQ(live[s].size(), expected[s].size()) << "scan " << s;
    for (std::size_t i = 0; i < live[s].size(); ++i) {
      const auto& a = live[s][i];
      const auto& b = expected[s][i];
      ASSERT_TRUE(a.x_m == b.x_m && a.y_m == b.y_m && a.z_m == b.z_m && a.azimuth_cdeg == b.azimuth_cdeg &&
                  a.laser_id == b.laser_id && a.intensity == b.intensity)
          << "scan " << s << " point " << i;
    }
    if (s > 0) {
      EXPECT_NEAR(spans_s[s], 0.1, 0.01) << "a 10 Hz rotation by the sensor's clock";
    }
  }
}

}  // namespace
}  // namespace msgraphs
