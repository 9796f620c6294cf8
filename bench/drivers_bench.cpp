// SPDX-License-Identifier: MIT
// Driver throughput on one core (goal: >= 100x the VLP-16 rate, 75,000 packets/s, ~30 M
// points/s) and the UDP receiver at 10x the VLP-16 packet rate on loopback:
//   build/host-release/bench/msgraphs_drivers_bench
// With MSGRAPHS_DATA_DIR set, the real einride recording is decoded as well.
#include <benchmark/benchmark.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

#include "msgraphs/drivers/can_odometry/candump.hpp"
#include "msgraphs/drivers/can_odometry/odometry_frames.hpp"
#include "msgraphs/drivers/can_odometry/odometry_integrator.hpp"
#include "msgraphs/drivers/can_odometry/sample_assembler.hpp"
#include "msgraphs/drivers/pcap/pcap_reader.hpp"
#include "msgraphs/drivers/pcap/udp_frame.hpp"
#include "msgraphs/drivers/velodyne/data_packet_decoder.hpp"
#include "msgraphs/drivers/velodyne/scan_assembler.hpp"
#include "msgraphs/platform/clock.hpp"
#include "msgraphs/platform/udp_socket.hpp"

namespace {

using namespace msgraphs;
namespace vel = msgraphs::drivers::velodyne;
namespace can = msgraphs::drivers::can_odometry;

// Synthetic VLP-16 packets with every channel returning (the worst case for the decoder).
std::vector<std::vector<std::uint8_t>> FullPackets(int n, std::uint8_t mode = 0x37) {
  std::vector<std::vector<std::uint8_t>> packets;
  for (int k = 0; k < n; ++k) {
    std::vector<std::uint8_t> p(vel::kDataPacketBytes, 0);
    for (int b = 0; b < 12; ++b) {
      const int firing = mode == 0x39 ? b / 2 : b;
      const auto az = static_cast<std::uint16_t>((k * 480 + firing * 40) % 36000);
      p[static_cast<std::size_t>(b) * 100] = 0xFF;
      p[static_cast<std::size_t>(b) * 100 + 1] = 0xEE;
      vel::WriteU16Le(&p[static_cast<std::size_t>(b) * 100 + 2], az);
      for (int c = 0; c < 32; ++c) {
        const std::size_t o = static_cast<std::size_t>(b) * 100 + 4 + static_cast<std::size_t>(c) * 3;
        vel::WriteU16Le(&p[o], static_cast<std::uint16_t>(1000 + ((k * 7 + c * 13 + b) % 4000) + (b % 2) * 40));
        p[o + 2] = static_cast<std::uint8_t>(c * 5);
      }
    }
    p[1204] = mode;
    p[1205] = 0x22;
    packets.push_back(std::move(p));
  }
  return packets;
}

void Decode(benchmark::State& state, const std::vector<std::vector<std::uint8_t>>& packets) {
  const auto decoder = vel::DataPacketDecoder::Create({}).value();
  std::vector<vel::VelodynePoint> out(vel::kMaxPointsPerPacket);
  std::size_t i = 0;
  std::int64_t points = 0;
  for (auto _ : state) {
    auto r = decoder.Decode(packets[i], out);
    points += r->points;
    benchmark::DoNotOptimize(out.data());
    if (++i == packets.size()) i = 0;
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["points/s"] = benchmark::Counter(static_cast<double>(points), benchmark::Counter::kIsRate);
  state.counters["x VLP-16 rate"] =
      benchmark::Counter(static_cast<double>(state.iterations()) / 753.5, benchmark::Counter::kIsRate);
}

void BM_DecodeVlp16FullPacket(benchmark::State& state) { Decode(state, FullPackets(64)); }
BENCHMARK(BM_DecodeVlp16FullPacket);

void BM_DecodeVlp16DualPacket(benchmark::State& state) { Decode(state, FullPackets(64, 0x39)); }
BENCHMARK(BM_DecodeVlp16DualPacket);

void BM_DecodeEinrideRecording(benchmark::State& state) {
  const char* dir = std::getenv("MSGRAPHS_DATA_DIR");
  std::vector<std::vector<std::uint8_t>> packets;
  if (dir != nullptr) {
    if (FILE* f = std::fopen((std::string(dir) + "/pcap/einride_vlp16_recording_1000pkts.bin").c_str(), "rb")) {
      std::vector<std::uint8_t> p(vel::kDataPacketBytes);
      while (std::fread(p.data(), 1, p.size(), f) == p.size()) packets.push_back(p);
      std::fclose(f);
    }
  }
  if (packets.empty()) {
    state.SkipWithError("MSGRAPHS_DATA_DIR not set or einride recording absent");
    return;
  }
  Decode(state, packets);
}
BENCHMARK(BM_DecodeEinrideRecording);

void BM_DecodeAndAssembleScans(benchmark::State& state) {
  const auto packets = FullPackets(75);  // one rotation
  const auto decoder = vel::DataPacketDecoder::Create({}).value();
  auto assembler = vel::ScanAssembler::Create({}).value();
  std::vector<vel::VelodynePoint> out(vel::kMaxPointsPerPacket);
  std::int64_t t = 0;
  std::size_t i = 0;
  for (auto _ : state) {
    auto r = decoder.Decode(packets[i], out).value();
    t += 1'327'104;
    benchmark::DoNotOptimize(assembler.AddPacket(UnixTime::FromNanoseconds(t), r, std::span(out).first(r.points)));
    if (++i == packets.size()) i = 0;
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_DecodeAndAssembleScans);

void BM_PcapReadAndExtractUdp(benchmark::State& state) {
  // An in-memory capture of 1000 framed VLP-16 packets.
  std::vector<std::uint8_t> file(drivers::pcap::kGlobalHeaderBytes);
  drivers::pcap::WriteGlobalHeader(std::span<std::uint8_t, 24>(file.data(), 24),
                                   drivers::pcap::TimestampPrecision::kMicroseconds, 65535,
                                   drivers::pcap::LinkType::kEthernet);
  const auto packets = FullPackets(1000);
  std::vector<std::uint8_t> frame(2000);
  for (const auto& p : packets) {
    const std::size_t n = drivers::pcap::BuildUdpFrame({1, 2368}, {2, 2368}, p, frame).value();
    const std::size_t at = file.size();
    file.resize(at + 16);
    drivers::pcap::WriteRecordHeader(std::span<std::uint8_t, 16>(file.data() + at, 16), UnixTime(),
                                     drivers::pcap::TimestampPrecision::kMicroseconds,
                                     static_cast<std::uint32_t>(n), static_cast<std::uint32_t>(n));
    file.insert(file.end(), frame.begin(), frame.begin() + static_cast<std::ptrdiff_t>(n));
  }
  std::int64_t records = 0;
  for (auto _ : state) {
    auto reader = drivers::pcap::PcapBufferReader::Open(file).value();
    drivers::pcap::PcapRecord record;
    drivers::pcap::PcapUdpCounters counters;
    while (reader.Next(record).value()) {
      benchmark::DoNotOptimize(drivers::pcap::ExtractUdp(reader.header(), record, counters));
    }
    records += static_cast<std::int64_t>(counters.records);
  }
  state.SetItemsProcessed(records);
}
BENCHMARK(BM_PcapReadAndExtractUdp);

void BM_CanFramesToPose(benchmark::State& state) {
  // One odometry sample: parse three candump lines, decode, pair, integrate.
  std::vector<std::string> lines;
  can::OdomSampleValues v;
  v.dx_m = 0.02;
  v.dyaw_rad = 0.001;
  for (int i = 0; i < 256; ++i) {
    v.sequence = static_cast<std::uint8_t>(i);
    v.sample_time_us += 20000;
    for (const can::CanFrame& f : can::EncodeOdomSample(v)) {
      char buffer[can::kMaxCandumpLine];
      const std::size_t n = can::FormatCandumpLine(UnixTime::FromNanoseconds(i * 20'000'000LL), "can0", f,
                                                   can::CandumpPrecision::kMicroseconds, buffer).value();
      lines.emplace_back(buffer, n);
    }
  }
  can::SampleAssembler assembler;
  auto integrator = can::OdometryIntegrator::Create({}).value();
  std::size_t i = 0;
  for (auto _ : state) {
    for (int k = 0; k < 3; ++k) {
      const auto line = can::ParseCandumpLine(lines[i]).value();
      const auto frame = can::DecodeOdomFrame(line.frame).value();
      if (assembler.Add(frame, line.stamp)) benchmark::DoNotOptimize(integrator.Add(assembler.sample()));
      if (++i == lines.size()) {
        i = 0;
        integrator = can::OdometryIntegrator::Create({}).value();  // the timeline restarts
      }
    }
  }
  state.SetItemsProcessed(state.iterations());
  state.SetLabel("samples (3 frames each)");
}
BENCHMARK(BM_CanFramesToPose);

// The UDP receiver against a sender pacing VLP-16 packets at 10x the sensor rate (7,535
// packets/s) on loopback for 2 s: reports received, kernel drops and loss.
void BM_UdpReceiverAt10xVlp16Rate(benchmark::State& state) {
  for (auto _ : state) {
    platform::UdpReceiverConfig config;
    config.bind = {kIpv4Loopback, 0};
    config.expected_payload_bytes = vel::kDataPacketBytes;
    auto receiver = platform::UdpReceiver::Open(config).value();
    auto sender = platform::UdpSender::Open({}).value();
    const Ipv4Endpoint to{kIpv4Loopback, receiver.bound_port()};
    constexpr int kPackets = 15070;  // 2 s at 10x
    const auto packets = FullPackets(64);
    std::atomic<bool> done{false};
    std::thread tx([&] {
      const SteadyTime start = platform::SteadyNow();
      for (int k = 0; k < kPackets; ++k) {
        platform::SleepUntil(start + Duration::FromNanoseconds(k * 132'710LL));
        static_cast<void>(sender.Send(to, packets[static_cast<std::size_t>(k) % packets.size()]));
      }
      done = true;
    });
    const auto decoder = vel::DataPacketDecoder::Create({}).value();
    std::vector<vel::VelodynePoint> out(vel::kMaxPointsPerPacket);
    std::int64_t received = 0;
    while (!done || received < kPackets) {
      const std::size_t n = receiver.Receive(platform::SteadyNow() + Duration::FromMilliseconds(200)).value();
      if (n == 0 && done) break;
      for (std::size_t i = 0; i < n; ++i) benchmark::DoNotOptimize(decoder.Decode(receiver.datagram(i).payload, out));
      received += static_cast<std::int64_t>(n);
    }
    tx.join();
    state.counters["sent"] = kPackets;
    state.counters["received"] = static_cast<double>(received);
    state.counters["kernel_drops"] = static_cast<double>(receiver.stats().kernel_drops);
    state.counters["peak_batch"] = static_cast<double>(receiver.stats().peak_batch);
  }
}
BENCHMARK(BM_UdpReceiverAt10xVlp16Rate)->Iterations(1)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
