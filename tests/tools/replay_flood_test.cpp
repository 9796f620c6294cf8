// SPDX-License-Identifier: MIT
// The real msgraphs_replay process floods a slow UdpReceiver on loopback: every datagram is
// either delivered or counted as a kernel drop; nothing crashes. Synthetic data only.
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
#include "../drivers/velodyne_test_packets.hpp"
#include "msgraphs/drivers/pcap/pcap_writer.hpp"
#include "msgraphs/drivers/velodyne/data_packet_decoder.hpp"
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


TEST(ReplayFlood, FloodingASlowReceiverGivesCountedDrops) {
  // A synthetic recording: 1000 VLP-16 packets (no external data needed).
  const std::string file = Temp("flood.pcap");
  {
    auto writer = drivers::pcap::PcapFileWriter::Create(file.c_str(), drivers::pcap::TimestampPrecision::kMicroseconds).value();
    for (int k = 0; k < 1000; ++k) {
      test::TestPacket p(static_cast<std::uint32_t>(k * 480) % 36000, 40);
      p.FillAll(static_cast<std::uint16_t>(1000 + k), 7);
      ASSERT_TRUE(writer.WriteUdp(UnixTime::FromNanoseconds(1'700'000'000'000'000'000 + k * 1'327'104LL),
                                  {0xC0A801C9, 2368}, {0xFFFFFFFF, 2368}, p.bytes));
    }
    ASSERT_TRUE(writer.Close());
  }
  auto data = Receiver(1206, 128 << 10);
  const pid_t replay = Spawn({MSGRAPHS_REPLAY_TOOL, "--pcap", file, "--to", "127.0.0.1", "--data-port",
                              std::to_string(data.bound_port()), "--position-port", "9", "--fast", "--loop", "20"});
  std::uint64_t received = 0;
  int code = -1;
  SteadyTime quiet_until = platform::SteadyNow() + Duration::FromSeconds(30.0);
  while (platform::SteadyNow() < quiet_until) {
    const std::size_t n = data.Receive(platform::SteadyNow() + Duration::FromMilliseconds(20)).value();
    received += n;
    std::this_thread::sleep_for(std::chrono::microseconds(500));  // a consumer slower than the flood
    if (code < 0 && Exited(replay, code)) quiet_until = platform::SteadyNow() + Duration::FromMilliseconds(300);
  }
  ASSERT_EQ(code, 0);
  // The kernel reports drops with the next datagram it queues: send one sentinel.
  auto sender = platform::UdpSender::Open({}).value();
  ASSERT_TRUE(sender.Send({kIpv4Loopback, data.bound_port()}, std::vector<std::uint8_t>(1206, 0)));
  received += data.Receive(platform::SteadyNow() + Duration::FromSeconds(1.0)).value();
  EXPECT_GT(data.stats().kernel_drops, 0u) << "the flood should overrun a 128 KiB buffer";
  EXPECT_EQ(received + data.stats().kernel_drops, 20u * 1000u + 1u);
  std::remove(file.c_str());
}

}  // namespace
}  // namespace msgraphs
