// SPDX-License-Identifier: MIT
// Loads the Velodyne traffic of a pcap (tests only): every UDP payload with its capture time
// and destination port.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "msgraphs/drivers/pcap/pcap_reader.hpp"

namespace msgraphs::test {

struct CapturedPayload {
  UnixTime time;
  std::uint16_t port = 0;
  std::vector<std::uint8_t> bytes;
};

struct Capture {
  std::vector<CapturedPayload> data;      ///< 1206-byte payloads
  std::vector<CapturedPayload> position;  ///< 512-byte payloads
  drivers::pcap::PcapUdpCounters counters;
  bool read_to_end = false;
};

inline Capture LoadCapture(const std::string& path) {
  Capture capture;
  auto reader = drivers::pcap::PcapFileReader::Open(path.c_str());
  if (!reader) return capture;
  drivers::pcap::PcapRecord record;
  for (;;) {
    auto next = reader->Next(record);
    if (!next) return capture;
    if (!*next) break;
    auto d = drivers::pcap::ExtractUdp(reader->header(), record, capture.counters);
    if (!d || d->payload_truncated) continue;
    CapturedPayload p{record.header.timestamp, d->destination.port, {d->payload.begin(), d->payload.end()}};
    if (p.bytes.size() == 1206) capture.data.push_back(std::move(p));
    if (p.bytes.size() == 512) capture.position.push_back(std::move(p));
  }
  capture.read_to_end = true;
  return capture;
}

}  // namespace msgraphs::test
