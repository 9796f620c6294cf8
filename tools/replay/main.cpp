// SPDX-License-Identifier: MIT
// msgraphs_replay: hardware-in-the-loop replay of a Velodyne pcap. Sends every data packet
// (1206-byte payload) to --to:--data-port and every position packet (512 bytes) to
// --to:--position-port, at the recorded pace scaled by --speed or as fast as possible (--fast),
// then prints a summary: packets, rate and timing error against the schedule.
//
//   msgraphs_replay --pcap run.pcap --to 127.0.0.1 [--speed 1.0 | --fast] [--loop N]
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "msgraphs/base/ipv4.hpp"
#include "msgraphs/drivers/can_odometry/candump.hpp"
#include "msgraphs/drivers/can_odometry/candump_file.hpp"
#include "msgraphs/drivers/pcap/pcap_reader.hpp"
#include "msgraphs/drivers/velodyne/packet_format.hpp"
#include "msgraphs/platform/clock.hpp"
#include "msgraphs/platform/udp_socket.hpp"

namespace {

using namespace msgraphs;
namespace velodyne = msgraphs::drivers::velodyne;
namespace pcap = msgraphs::drivers::pcap;
namespace can_odometry = msgraphs::drivers::can_odometry;

struct Options {
  std::string pcap_path;
  std::uint32_t to = kIpv4Loopback;
  std::uint16_t data_port = velodyne::kDefaultDataPort;
  std::uint16_t position_port = velodyne::kDefaultPositionPort;
  double speed = 1.0;
  bool fast = false;
  int loops = 1;
  bool broadcast = false;
  std::string candump_path;  ///< CAN odometry sent alongside, one candump line a datagram
  std::uint16_t can_port = 20000;
};

void Usage() {
  std::fprintf(
      stderr,
      "usage: msgraphs_replay --pcap FILE [--to ADDR] [--data-port P] [--position-port P]\n"
      "                       [--speed X | --fast] [--loop N] [--broadcast]\n"
      "                       [--candump FILE [--can-port P]]\n"
      "  --to ADDR        destination IPv4 address (default 127.0.0.1)\n"
      "  --speed X        pace relative to the recording (0.5, 1, 2, ...; default 1)\n"
      "  --fast           as fast as possible (batched sendmmsg)\n"
      "  --loop N         replay the file N times (timestamps continue)\n"
      "  --candump FILE   also send the recording's CAN odometry, one candump line per UDP\n"
      "                   datagram to --can-port (default 20000), on the same schedule\n"
      "                   (a CAN-to-Ethernet gateway's stream; needs --speed 1, one loop)\n");
}

bool ParseOptions(int argc, char** argv, Options& o) {
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> const char* { return i + 1 < argc ? argv[++i] : nullptr; };
    if (a == "--pcap") {
      const char* v = value();
      if (v == nullptr) return false;
      o.pcap_path = v;
    } else if (a == "--to") {
      auto address = ParseIpv4Address(value());
      if (!address) return false;
      o.to = *address;
    } else if (a == "--data-port" || a == "--position-port") {
      const char* v = value();
      const long port = v != nullptr ? std::strtol(v, nullptr, 10) : 0;
      if (port <= 0 || port > 65535) return false;
      (a == "--data-port" ? o.data_port : o.position_port) = static_cast<std::uint16_t>(port);
    } else if (a == "--speed") {
      const char* v = value();
      o.speed = v != nullptr ? std::strtod(v, nullptr) : 0.0;
      if (!(o.speed > 0.0) || o.speed > 1000.0) return false;
    } else if (a == "--fast") {
      o.fast = true;
    } else if (a == "--loop") {
      const char* v = value();
      o.loops = v != nullptr ? std::atoi(v) : 0;
      if (o.loops < 1) return false;
    } else if (a == "--broadcast") {
      o.broadcast = true;
    } else if (a == "--candump") {
      const char* v = value();
      if (v == nullptr) return false;
      o.candump_path = v;
    } else if (a == "--can-port") {
      const char* v = value();
      const long port = v != nullptr ? std::strtol(v, nullptr, 10) : 0;
      if (port <= 0 || port > 65535) return false;
      o.can_port = static_cast<std::uint16_t>(port);
    } else {
      return false;
    }
  }
  // The receiver stamps odometry by arrival: only the recorded pace keeps its velocities true.
  if (!o.candump_path.empty() && (o.fast || o.speed != 1.0 || o.loops != 1)) return false;
  return !o.pcap_path.empty();
}

enum class Kind : std::uint8_t { kData, kPosition, kCan };

struct Packet {
  std::int64_t offset_ns;  // from the first packet or frame of the recording
  Kind kind;
  std::vector<std::uint8_t> payload;
};

double Percentile(std::vector<double>& v, double q) {
  if (v.empty()) return 0.0;
  const auto k = static_cast<std::size_t>(q * static_cast<double>(v.size() - 1));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

}  // namespace

int main(int argc, char** argv) {
  Options options;
  if (!ParseOptions(argc, argv, options)) {
    Usage();
    return 2;
  }

  // Load the Velodyne traffic first so that file I/O never disturbs the pacing.
  auto reader = pcap::PcapFileReader::Open(options.pcap_path.c_str());
  if (!reader) {
    std::fprintf(stderr, "replay: %s: %s (%s)\n", options.pcap_path.c_str(), reader.error().detail,
                 std::strerror(reader.error().sys_errno));
    return 1;
  }
  std::vector<Packet> packets;
  pcap::PcapUdpCounters counters;
  std::uint64_t other_udp = 0;
  std::int64_t first_ns = 0;
  pcap::PcapRecord record;
  bool truncated_file = false;
  for (;;) {
    auto next = reader->Next(record);
    if (!next) {
      std::fprintf(stderr, "replay: %s: %s after %llu records; replaying what came before\n",
                   options.pcap_path.c_str(), next.error().detail,
                   static_cast<unsigned long long>(reader->records()));
      truncated_file = true;
      break;
    }
    if (!*next) break;
    auto d = pcap::ExtractUdp(reader->header(), record, counters);
    if (!d || d->payload_truncated) continue;
    const std::size_t n = d->payload.size();
    if (n != velodyne::kDataPacketBytes && n != velodyne::kPositionPacketBytes) {
      ++other_udp;
      continue;
    }
    const std::int64_t t = record.header.timestamp.nanoseconds_since_epoch();
    packets.push_back({t,
                       n == velodyne::kDataPacketBytes ? Kind::kData : Kind::kPosition,
                       {d->payload.begin(), d->payload.end()}});
  }
  std::uint64_t can_frames = 0;
  if (!options.candump_path.empty()) {
    // The odometry log shares the recording's clock with the capture: merged by time.
    auto log = can_odometry::CandumpFileReader::Open(options.candump_path.c_str());
    if (!log) {
      std::fprintf(stderr, "replay: %s: %s\n", options.candump_path.c_str(), log.error().detail);
      return 1;
    }
    can_odometry::CandumpLine line;
    char text[can_odometry::kMaxCandumpLine];
    while (log->Next(line).value_or(false)) {
      auto n = can_odometry::FormatCandumpLine(line.stamp, line.interface_name(), line.frame,
                                               can_odometry::CandumpPrecision::kMicroseconds, text);
      if (!n) continue;
      packets.push_back({line.stamp.nanoseconds_since_epoch(),
                         Kind::kCan,
                         {reinterpret_cast<const std::uint8_t*>(text),
                          reinterpret_cast<const std::uint8_t*>(text) + *n}});
      ++can_frames;
    }
  }
  std::stable_sort(packets.begin(), packets.end(),
                   [](const Packet& a, const Packet& b) { return a.offset_ns < b.offset_ns; });
  if (!packets.empty()) first_ns = packets.front().offset_ns;
  for (Packet& p : packets) p.offset_ns -= first_ns;
  if (packets.empty()) {
    std::fprintf(stderr, "replay: no Velodyne packets in %s\n", options.pcap_path.c_str());
    return 1;
  }
  // Capture timestamps can step backwards (several capture threads); pace by the maximum so far.
  for (std::size_t i = 1; i < packets.size(); ++i) {
    packets[i].offset_ns = std::max(packets[i].offset_ns, packets[i - 1].offset_ns);
  }
  const std::int64_t file_span_ns = packets.back().offset_ns;
  // Between loops keep one typical packet gap so the rate stays that of the recording.
  const std::int64_t loop_gap_ns =
      packets.size() > 1 ? file_span_ns / static_cast<std::int64_t>(packets.size() - 1) : 1'000'000;

  platform::UdpSenderConfig sender_config;
  sender_config.allow_broadcast = options.broadcast;
  auto sender = platform::UdpSender::Open(sender_config);
  if (!sender) {
    std::fprintf(stderr, "replay: %s (%s)\n", sender.error().detail,
                 std::strerror(sender.error().sys_errno));
    return 1;
  }
  const Ipv4Endpoint data_to{options.to, options.data_port};
  const Ipv4Endpoint position_to{options.to, options.position_port};
  const Ipv4Endpoint can_to{options.to, options.can_port};

  std::vector<double> error_us;
  error_us.reserve(packets.size() * static_cast<std::size_t>(options.loops));
  std::uint64_t data_sent = 0, position_sent = 0, can_sent = 0;
  const SteadyTime start = platform::SteadyNow();
  // The schedule's anchor, so that a receiver's stamps can be compared with the recording's.
  std::printf("replay: recording time %.6f is sent at host time %.6f\n",
              static_cast<double>(first_ns) * 1e-9, platform::UnixNow().seconds_since_epoch());
  std::fflush(stdout);
  for (int loop = 0; loop < options.loops; ++loop) {
    const std::int64_t loop_offset_ns = loop * (file_span_ns + loop_gap_ns);
    for (const Packet& p : packets) {
      const Ipv4Endpoint& to = p.kind == Kind::kData       ? data_to
                               : p.kind == Kind::kPosition ? position_to
                                                           : can_to;
      if (options.fast) {
        if (!sender->Queue(to, p.payload)) {
          if (Status s = sender->SendQueued(); !s) {
            std::fprintf(stderr, "replay: send failed: %s\n", std::strerror(s.error().sys_errno));
            return 1;
          }
          static_cast<void>(sender->Queue(to, p.payload));
        }
      } else {
        const auto scheduled_ns = static_cast<std::int64_t>(
            static_cast<double>(p.offset_ns + loop_offset_ns) / options.speed);
        const SteadyTime due = start + Duration::FromNanoseconds(scheduled_ns);
        // Sleep to just before the deadline, then spin: nanosleep alone is ~60 us late.
        const SteadyTime wake = due - Duration::FromMicroseconds(200);
        if (platform::SteadyNow() < wake) platform::SleepUntil(wake);
        while (platform::SteadyNow() < due) {
        }
        error_us.push_back(static_cast<double>((platform::SteadyNow() - due).nanoseconds()) * 1e-3);
        if (Status s = sender->Send(to, p.payload); !s) {
          std::fprintf(stderr, "replay: send failed: %s\n", std::strerror(s.error().sys_errno));
          return 1;
        }
      }
      (p.kind == Kind::kData ? data_sent : p.kind == Kind::kPosition ? position_sent : can_sent)++;
    }
  }
  if (options.fast) {
    if (Status s = sender->SendQueued(); !s) {
      std::fprintf(stderr, "replay: send failed: %s\n", std::strerror(s.error().sys_errno));
      return 1;
    }
  }
  const double elapsed_s = (platform::SteadyNow() - start).seconds();
  const std::uint64_t sent = data_sent + position_sent + can_sent;
  const auto to_text = FormatIpv4Address(options.to);

  char pace[48];
  if (options.fast) {
    std::snprintf(pace, sizeof(pace), "as fast as possible");
  } else {
    std::snprintf(pace, sizeof(pace), "speed %.2fx", options.speed);
  }
  std::printf("replay: %s -> %s (data port %u, position port %u), %s\n", options.pcap_path.c_str(),
              to_text.data(), options.data_port, options.position_port, pace);
  std::printf(
      "  packets: %llu data, %llu position sent; skipped %llu other UDP, %llu non-UDP, %llu "
      "malformed frames%s\n",
      static_cast<unsigned long long>(data_sent), static_cast<unsigned long long>(position_sent),
      static_cast<unsigned long long>(other_udp),
      static_cast<unsigned long long>(counters.other_traffic),
      static_cast<unsigned long long>(counters.malformed_frames),
      truncated_file ? " (file truncated)" : "");
  if (!options.candump_path.empty())
    std::printf("  CAN odometry: %llu of %llu frames sent to port %u\n",
                static_cast<unsigned long long>(can_sent),
                static_cast<unsigned long long>(can_frames), options.can_port);
  std::printf("  time: %.3f s for %.3f s of recording x %d; rate %.0f packets/s, %.1f Mbit/s\n",
              elapsed_s, static_cast<double>(file_span_ns) * 1e-9, options.loops,
              static_cast<double>(sent) / elapsed_s,
              static_cast<double>(sender->stats().bytes) * 8e-6 / elapsed_s);
  if (!options.fast) {
    std::vector<double> e = error_us;
    std::printf("  timing error vs schedule: p50 %.1f us, p99 %.1f us, max %.1f us\n",
                Percentile(e, 0.5), Percentile(e, 0.99),
                *std::max_element(error_us.begin(), error_us.end()));
  }
  return 0;
}
