// SPDX-License-Identifier: MIT
// The complete VLP-16 sweeps of a recorded pcap, through the real drivers (UDP extraction,
// decoding, device clock, scan assembly), for the host tools that evaluate on recordings.
#pragma once

#include <memory>
#include <span>
#include <string>
#include <vector>

#include "msgraphs/drivers/pcap/pcap_reader.hpp"
#include "msgraphs/drivers/velodyne/data_packet_decoder.hpp"
#include "msgraphs/drivers/velodyne/device_clock.hpp"
#include "msgraphs/drivers/velodyne/scan_assembler.hpp"

namespace msgraphs::tools {

class RecordedScans {
 public:
  /// nullptr when the file cannot be opened or is not a pcap.
  static std::unique_ptr<RecordedScans> Open(const std::string& pcap_path) {
    auto reader = drivers::pcap::PcapFileReader::Open(pcap_path.c_str());
    if (!reader) return nullptr;
    return std::unique_ptr<RecordedScans>(new RecordedScans(std::move(*reader)));
  }

  /// The next complete sweep, or nullptr at the end of the file (incomplete sweeps are skipped).
  const drivers::velodyne::Scan* Next() {
    while (reader_.Next(record_).value_or(false)) {
      auto d = drivers::pcap::ExtractUdp(reader_.header(), record_, counters_);
      if (!d || d->payload.size() != drivers::velodyne::kDataPacketBytes) continue;
      auto decoded = decoder_.Decode(d->payload, packet_);
      if (!decoded) continue;
      const UnixTime first =
          sync_.Map(record_.header.timestamp, decoded->device_time_us, decoded->packet_duration_ns);
      if (!assembler_.AddPacket(first, *decoded, std::span(packet_).first(decoded->points)))
        continue;
      if (assembler_.completed().complete) return &assembler_.completed();
    }
    return nullptr;
  }

 private:
  explicit RecordedScans(drivers::pcap::PcapFileReader reader)
      : reader_(std::move(reader)),
        decoder_(drivers::velodyne::DataPacketDecoder::Create({}).value()),
        assembler_(drivers::velodyne::ScanAssembler::Create({}).value()),
        packet_(drivers::velodyne::kMaxPointsPerPacket) {}

  drivers::pcap::PcapFileReader reader_;
  drivers::velodyne::DataPacketDecoder decoder_;
  drivers::velodyne::ScanAssembler assembler_;
  drivers::velodyne::DeviceClockSync sync_;
  std::vector<drivers::velodyne::VelodynePoint> packet_;
  drivers::pcap::PcapRecord record_;
  drivers::pcap::PcapUdpCounters counters_;
};

}  // namespace msgraphs::tools
