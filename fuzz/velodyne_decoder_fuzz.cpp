// SPDX-License-Identifier: MIT
// libFuzzer target: arbitrary bytes as Velodyne data and position packets, through every
// decoder configuration and the scan assembler. Invariants: no crash, no point outside the
// output buffer, every delivered point finite and within the configured range.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "msgraphs/drivers/velodyne/data_packet_decoder.hpp"
#include "msgraphs/drivers/velodyne/position_packet.hpp"
#include "msgraphs/drivers/velodyne/scan_assembler.hpp"

using namespace msgraphs;
using namespace msgraphs::drivers::velodyne;

namespace {
struct State {
  DataPacketDecoder vlp16 = DataPacketDecoder::Create({}).value();
  DataPacketDecoder hdl32 = DataPacketDecoder::Create({SensorModel::kHdl32e, 0.5, 100.0, false, false}).value();
  ScanAssembler assembler = ScanAssembler::Create({}).value();
  std::vector<VelodynePoint> out = std::vector<VelodynePoint>(kMaxPointsPerPacket);
  std::int64_t t_ns = 1'700'000'000'000'000'000;
};
State& GetState() {
  static State state;
  return state;
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  State& s = GetState();
  // Exercise the exact-size paths even when the fuzzer's input has another length.
  std::uint8_t packet[kDataPacketBytes] = {};
  std::memcpy(packet, data, size < sizeof(packet) ? size : sizeof(packet));
  for (const DataPacketDecoder* decoder : {&s.vlp16, &s.hdl32}) {
    for (std::span<const std::uint8_t> bytes : {std::span<const std::uint8_t>(data, size), std::span<const std::uint8_t>(packet)}) {
      auto r = decoder->Decode(bytes, s.out);
      if (!r) continue;
      if (r->points > kMaxPointsPerPacket) std::abort();
      const double min_r = decoder->config().min_range_m, max_r = decoder->config().max_range_m;
      for (std::size_t i = 0; i < r->points; ++i) {
        const VelodynePoint& p = s.out[i];
        if (!std::isfinite(p.x_m) || !std::isfinite(p.y_m) || !std::isfinite(p.z_m)) std::abort();
        const auto range = static_cast<double>(p.range_m);
        if (range < min_r - 1e-3 || range > max_r + 1e-3 || p.azimuth_cdeg >= 36000) std::abort();
      }
      s.t_ns += size > 0 ? (data[0] * 10000) - 500000 : 1000;  // also goes backwards sometimes
      static_cast<void>(s.assembler.AddPacket(UnixTime::FromNanoseconds(s.t_ns), *r, std::span(s.out).first(r->points)));
    }
  }
  std::uint8_t position[kPositionPacketBytes] = {};
  std::memcpy(position, data, size < sizeof(position) ? size : sizeof(position));
  auto p = DecodePositionPacket(position);
  if (p && p->nmea_length > 128) std::abort();
  static_cast<void>(ParseNmea({reinterpret_cast<const char*>(data), size}));
  return 0;
}
