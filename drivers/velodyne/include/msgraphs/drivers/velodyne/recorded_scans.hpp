// SPDX-License-Identifier: MIT
// The complete VLP-16 sweeps of a recorded pcap, through the real drivers (UDP extraction,
// decoding, device clock, scan assembly): the node's recorded LiDAR input and the host tools'.
#pragma once

#include <memory>
#include <span>
#include <string>
#include <vector>

#include "msgraphs/drivers/pcap/pcap_reader.hpp"
#include "msgraphs/drivers/velodyne/data_packet_decoder.hpp"
#include "msgraphs/drivers/velodyne/device_clock.hpp"
#include "msgraphs/drivers/velodyne/scan_assembler.hpp"

namespace msgraphs::drivers::velodyne {

class RecordedScans {
 public:
  /// nullptr when the file cannot be opened or is not a pcap.
  static std::unique_ptr<RecordedScans> Open(const std::string& pcap_path) {
    auto reader = pcap::PcapFileReader::Open(pcap_path.c_str());
    if (!reader) return nullptr;
    return std::unique_ptr<RecordedScans>(new RecordedScans(std::move(*reader)));
  }

  /// The next complete sweep, or nullptr at the end of the file (incomplete sweeps are skipped).
  const Scan* Next() {
    while (reader_.Next(record_).value_or(false)) {
      auto d = pcap::ExtractUdp(reader_.header(), record_, counters_);
      if (!d || d->payload.size() != kDataPacketBytes) continue;
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
  explicit RecordedScans(pcap::PcapFileReader reader)
      : reader_(std::move(reader)),
        decoder_(DataPacketDecoder::Create({}).value()),
        assembler_(ScanAssembler::Create({}).value()),
        packet_(kMaxPointsPerPacket) {}

  pcap::PcapFileReader reader_;
  DataPacketDecoder decoder_;
  ScanAssembler assembler_;
  DeviceClockSync sync_;
  std::vector<VelodynePoint> packet_;
  pcap::PcapRecord record_;
  pcap::PcapUdpCounters counters_;
};

}  // namespace msgraphs::drivers::velodyne
