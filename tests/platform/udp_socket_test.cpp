// SPDX-License-Identifier: MIT
// UDP receiver and sender on loopback: batched receive with kernel timestamps, filtering and
// truncation counters, kernel drop counting when flooded, deadlines, zero allocation per batch.
#include <gtest/gtest.h>

#include <vector>

#include "alloc_counter.hpp"
#include "msgraphs/platform/clock.hpp"
#include "msgraphs/platform/udp_socket.hpp"

namespace msgraphs::platform {
namespace {

UdpReceiver OpenReceiver(UdpReceiverConfig config = {}) {
  config.bind = {kIpv4Loopback, 0};
  auto r = UdpReceiver::Open(config);
  EXPECT_TRUE(r.has_value()) << (r ? "" : r.error().detail);
  return std::move(r).value();
}

UdpSender OpenSender() { return UdpSender::Open({}).value(); }

std::vector<std::uint8_t> Bytes(std::size_t n, std::uint8_t seed) {
  std::vector<std::uint8_t> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = static_cast<std::uint8_t>(seed + i);
  return v;
}

SteadyTime In(int ms) { return SteadyNow() + Duration::FromMilliseconds(ms); }

TEST(UdpSocket, BatchedReceiveWithKernelTimestamps) {
  auto receiver = OpenReceiver();
  // Native Linux always grants both; only an emulator may refuse them.
  RecordProperty("kernel_timestamps", receiver.stats().kernel_timestamps ? "yes" : "no (emulator)");
  auto sender = OpenSender();
  const Ipv4Endpoint to{kIpv4Loopback, receiver.bound_port()};
  const UnixTime before = UnixNow();
  for (int i = 0; i < 100; ++i) ASSERT_TRUE(sender.Queue(to, Bytes(1206, static_cast<std::uint8_t>(i))) ||
                                            (sender.SendQueued() && sender.Queue(to, Bytes(1206, static_cast<std::uint8_t>(i)))));
  ASSERT_TRUE(sender.SendQueued());
  std::size_t got = 0;
  while (got < 100) {
    const std::size_t n = receiver.Receive(In(1000)).value();
    ASSERT_GT(n, 0u);
    for (std::size_t i = 0; i < n; ++i) {
      const ReceivedDatagram& d = receiver.datagram(i);
      ASSERT_EQ(d.payload.size(), 1206u);
      EXPECT_EQ(d.payload[0], static_cast<std::uint8_t>(got + i));
      EXPECT_EQ(d.source.address, kIpv4Loopback);
      EXPECT_GE(d.kernel_time, before);
      EXPECT_LE(d.kernel_time, UnixNow());
    }
    got += n;
  }
  EXPECT_EQ(receiver.stats().datagrams, 100u);
  EXPECT_GT(receiver.stats().peak_batch, 1u) << "recvmmsg should return batches";
  EXPECT_EQ(sender.stats().datagrams, 100u);
}

TEST(UdpSocket, ForeignAndOversizedDatagramsAreCountedNotDelivered) {
  UdpReceiverConfig config;
  config.expected_payload_bytes = 1206;
  config.max_payload_bytes = 1500;
  auto receiver = OpenReceiver(config);
  auto sender = OpenSender();
  const Ipv4Endpoint to{kIpv4Loopback, receiver.bound_port()};
  ASSERT_TRUE(sender.Send(to, Bytes(512, 1)));    // wrong size: foreign
  ASSERT_TRUE(sender.Send(to, Bytes(4000, 2)));   // beyond max: truncated
  ASSERT_TRUE(sender.Send(to, Bytes(1206, 3)));   // the one to deliver
  const std::size_t n = receiver.Receive(In(1000)).value();
  ASSERT_EQ(n, 1u);
  EXPECT_EQ(receiver.datagram(0).payload[0], 3);
  EXPECT_EQ(receiver.stats().foreign, 1u);
  EXPECT_EQ(receiver.stats().truncated, 1u);
}

TEST(UdpSocket, SourceFilterRejectsOtherSenders) {
  UdpReceiverConfig config;
  config.expected_source = 0x7F000002;  // 127.0.0.2, not our sender
  auto receiver = OpenReceiver(config);
  auto sender = OpenSender();
  ASSERT_TRUE(sender.Send({kIpv4Loopback, receiver.bound_port()}, Bytes(100, 0)));
  EXPECT_EQ(receiver.Receive(In(100)).value(), 0u);
  EXPECT_EQ(receiver.stats().foreign, 1u);
}

TEST(UdpSocket, DeadlinePassesWithNothingReceived) {
  auto receiver = OpenReceiver();
  const SteadyTime start = SteadyNow();
  EXPECT_EQ(receiver.Receive(start + Duration::FromMilliseconds(30)).value(), 0u);
  EXPECT_GE(SteadyNow() - start, Duration::FromMilliseconds(29));
}

TEST(UdpSocket, FloodingASmallBufferCountsKernelDrops) {
  UdpReceiverConfig config;
  config.receive_buffer_bytes = 64 << 10;  // a few dozen datagrams
  auto receiver = OpenReceiver(config);
  if (!receiver.stats().drop_counting) GTEST_SKIP() << "SO_RXQ_OVFL refused (qemu-user): drops cannot be counted here";
  auto sender = OpenSender();
  const Ipv4Endpoint to{kIpv4Loopback, receiver.bound_port()};
  const auto payload = Bytes(1206, 0);
  constexpr int kSent = 2000;
  for (int i = 0; i < kSent; ++i) ASSERT_TRUE(sender.Send(to, payload));  // nobody reads meanwhile
  std::uint64_t received = 0;
  for (;;) {
    const std::size_t n = receiver.Receive(In(50)).value();
    if (n == 0) break;
    received += n;
  }
  // The kernel reports the drop count with the next datagram it queues (SO_RXQ_OVFL), so
  // one more datagram after the flood carries it.
  ASSERT_TRUE(sender.Send(to, payload));
  received += receiver.Receive(In(1000)).value();
  EXPECT_GT(receiver.stats().kernel_drops, 0u);
  EXPECT_EQ(received + receiver.stats().kernel_drops, static_cast<std::uint64_t>(kSent + 1))
      << "every datagram is either delivered or counted as dropped";
}

TEST(UdpSocket, ReceivingAllocatesNothing) {
  auto receiver = OpenReceiver();
  auto sender = OpenSender();
  const Ipv4Endpoint to{kIpv4Loopback, receiver.bound_port()};
  const auto payload = Bytes(1206, 0);
  test::AllocationScope scope;
  std::size_t got = 0;
  for (int round = 0; round < 10; ++round) {
    for (int i = 0; i < 20; ++i) ASSERT_TRUE(sender.Send(to, payload));
    while (got < static_cast<std::size_t>(20 * (round + 1))) got += receiver.Receive(In(1000)).value();
  }
  EXPECT_EQ(scope.allocations(), 0u);
  EXPECT_EQ(got, 200u);
}

// udp_socket.hpp: "All buffers are allocated at Open": the batched path too. Each round queues
// `batch` datagrams, finds the queue full, sends them with sendmmsg and reads them back.
TEST(UdpSocket, QueueingAndSendingABatchAllocatesNothing) {
  auto receiver = OpenReceiver();
  UdpSenderConfig config;
  config.batch = 16;
  auto sender = UdpSender::Open(config).value();
  const Ipv4Endpoint to{kIpv4Loopback, receiver.bound_port()};
  const auto payload = Bytes(1206, 0);
  std::size_t got = 0;
  bool queued = true, full_refused = true, sent = true;
  std::uint64_t allocations = 0;
  {
    test::AllocationScope scope;
    for (int round = 0; round < 5; ++round) {
      for (std::size_t i = 0; i < config.batch; ++i) queued = queued && sender.Queue(to, payload).has_value();
      full_refused = full_refused && !sender.Queue(to, payload).has_value();
      sent = sent && sender.SendQueued().has_value();
      for (std::size_t n = 1; n > 0 && got < config.batch * static_cast<std::size_t>(round + 1);) {
        n = receiver.Receive(In(1000)).value();  // 0 after a second without any: stop, the count says
        got += n;
      }
    }
    allocations = scope.allocations();
  }
  EXPECT_EQ(allocations, 0u);
  EXPECT_TRUE(queued && full_refused && sent);
  EXPECT_EQ(got, 5 * config.batch);
  EXPECT_EQ(sender.stats().datagrams, 5 * config.batch);
}

TEST(UdpSocket, BindConflictIsAClearError) {
  UdpReceiverConfig config;
  config.allow_address_reuse = false;
  auto first = OpenReceiver(config);
  config.bind = {kIpv4Loopback, first.bound_port()};
  auto second = UdpReceiver::Open(config);
  ASSERT_FALSE(second.has_value());
  EXPECT_EQ(second.error().code, Errc::kIo);
  EXPECT_NE(second.error().sys_errno, 0);
}

TEST(UdpSocket, BadConfigIsRejected) {
  UdpReceiverConfig config;
  config.batch = 0;
  EXPECT_EQ(UdpReceiver::Open(config).error().code, Errc::kInvalidConfig);
  config = {};
  config.expected_payload_bytes = 5000;
  EXPECT_EQ(UdpReceiver::Open(config).error().code, Errc::kInvalidConfig);
}

}  // namespace
}  // namespace msgraphs::platform
