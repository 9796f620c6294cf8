// SPDX-License-Identifier: MIT
// msgraphs_record: records Velodyne UDP traffic (data and position ports) into a classic pcap
// with the kernel's receive timestamps, the format msgraphs_replay, tcpdump and VeloView read.
// Stops after --duration-s, after --packets data packets, or on SIGINT/SIGTERM.
//
//   msgraphs_record --out run.pcap [--bind ADDR] [--data-port P] [--position-port P]
//                   [--duration-s S] [--packets N] [--ns]
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "msgraphs/base/ipv4.hpp"
#include "msgraphs/drivers/pcap/pcap_writer.hpp"
#include "msgraphs/drivers/velodyne/packet_format.hpp"
#include "msgraphs/platform/clock.hpp"
#include "msgraphs/platform/udp_socket.hpp"

namespace {

using namespace msgraphs;
volatile std::sig_atomic_t g_stop = 0;
void OnSignal(int) { g_stop = 1; }

struct Options {
  std::string out;
  std::uint32_t bind = kIpv4Any;
  std::uint16_t data_port = drivers::velodyne::kDefaultDataPort;
  std::uint16_t position_port = drivers::velodyne::kDefaultPositionPort;
  double duration_s = 0;  // 0: until a signal
  std::uint64_t packets = 0;
  bool nanoseconds = false;
};

bool Parse(int argc, char** argv, Options& o) {
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const char* v = i + 1 < argc ? argv[i + 1] : nullptr;
    if (a == "--ns") {
      o.nanoseconds = true;
      continue;
    }
    if (v == nullptr) return false;
    ++i;
    if (a == "--out") {
      o.out = v;
    } else if (a == "--bind") {
      auto address = ParseIpv4Address(v);
      if (!address) return false;
      o.bind = *address;
    } else if (a == "--data-port" || a == "--position-port") {
      const long port = std::strtol(v, nullptr, 10);
      if (port <= 0 || port > 65535) return false;
      (a == "--data-port" ? o.data_port : o.position_port) = static_cast<std::uint16_t>(port);
    } else if (a == "--duration-s") {
      o.duration_s = std::strtod(v, nullptr);
      if (!(o.duration_s > 0)) return false;
    } else if (a == "--packets") {
      o.packets = std::strtoull(v, nullptr, 10);
      if (o.packets == 0) return false;
    } else {
      return false;
    }
  }
  return !o.out.empty();
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  if (!Parse(argc, argv, o)) {
    std::fprintf(stderr,
                 "usage: msgraphs_record --out FILE [--bind ADDR] [--data-port P] [--position-port P]\n"
                 "                       [--duration-s S] [--packets N] [--ns]\n");
    return 2;
  }
  std::signal(SIGINT, OnSignal);
  std::signal(SIGTERM, OnSignal);

  platform::UdpReceiver* receivers[2] = {nullptr, nullptr};
  auto open = [&](std::uint16_t port, std::size_t size) {
    platform::UdpReceiverConfig c;
    c.bind = {o.bind, port};
    c.expected_payload_bytes = size;
    return platform::UdpReceiver::Open(c);
  };
  auto data = open(o.data_port, drivers::velodyne::kDataPacketBytes);
  auto position = open(o.position_port, drivers::velodyne::kPositionPacketBytes);
  if (!data || !position) {
    const Error& e = !data ? data.error() : position.error();
    std::fprintf(stderr, "record: %s (%s)\n", e.detail, std::strerror(e.sys_errno));
    return 1;
  }
  receivers[0] = &*data;
  receivers[1] = &*position;
  auto writer = drivers::pcap::PcapFileWriter::Create(
      o.out.c_str(), o.nanoseconds ? drivers::pcap::TimestampPrecision::kNanoseconds
                                   : drivers::pcap::TimestampPrecision::kMicroseconds);
  if (!writer) {
    std::fprintf(stderr, "record: %s: %s (%s)\n", o.out.c_str(), writer.error().detail,
                 std::strerror(writer.error().sys_errno));
    return 1;
  }
  std::printf("record: listening on ports %u (data) and %u (position), writing %s\n", o.data_port,
              o.position_port, o.out.c_str());
  std::fflush(stdout);

  const SteadyTime start = platform::SteadyNow();
  const SteadyTime end = o.duration_s > 0 ? start + Duration::FromSeconds(o.duration_s)
                                          : SteadyTime::FromNanoseconds(INT64_MAX);
  const std::uint32_t destination = o.bind == kIpv4Any ? 0xFFFFFFFFu : o.bind;
  std::uint64_t written[2] = {0, 0};
  while (g_stop == 0 && platform::SteadyNow() < end && (o.packets == 0 || written[0] < o.packets)) {
    // Poll in short slices so that signals and the duration are honoured promptly.
    SteadyTime slice = platform::SteadyNow() + Duration::FromMilliseconds(100);
    if (slice > end) slice = end;
    const int fds[2] = {receivers[0]->fd(), receivers[1]->fd()};
    auto ready = platform::WaitReadable(fds, slice);
    if (!ready) {
      std::fprintf(stderr, "record: %s\n", ready.error().detail);
      return 1;
    }
    for (int k = 0; k < 2; ++k) {
      if ((*ready & (1u << k)) == 0) continue;
      auto n = receivers[k]->Receive(platform::SteadyNow());
      if (!n) {
        std::fprintf(stderr, "record: %s (%s)\n", n.error().detail, std::strerror(n.error().sys_errno));
        return 1;
      }
      for (std::size_t i = 0; i < *n; ++i) {
        const platform::ReceivedDatagram& d = receivers[k]->datagram(i);
        const std::uint16_t port = k == 0 ? o.data_port : o.position_port;
        if (Status s = writer->WriteUdp(d.kernel_time, d.source, {destination, port}, d.payload); !s) {
          std::fprintf(stderr, "record: write failed: %s (%s)\n", s.error().detail, std::strerror(s.error().sys_errno));
          return 1;
        }
        ++written[k];
      }
    }
  }
  if (Status s = writer->Close(); !s) {
    std::fprintf(stderr, "record: %s (%s)\n", s.error().detail, std::strerror(s.error().sys_errno));
    return 1;
  }
  const auto& ds = receivers[0]->stats();
  const auto& ps = receivers[1]->stats();
  std::printf("record: %llu data + %llu position packets in %.2f s; dropped by the kernel %llu, foreign %llu, truncated %llu\n",
              static_cast<unsigned long long>(written[0]), static_cast<unsigned long long>(written[1]),
              (platform::SteadyNow() - start).seconds(),
              static_cast<unsigned long long>(ds.kernel_drops + ps.kernel_drops),
              static_cast<unsigned long long>(ds.foreign + ps.foreign),
              static_cast<unsigned long long>(ds.truncated + ps.truncated));
  return 0;
}
