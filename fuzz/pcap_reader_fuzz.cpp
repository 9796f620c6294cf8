// SPDX-License-Identifier: MIT
// libFuzzer target: arbitrary bytes as a pcap file. Invariants: no crash, every record lies
// inside the input, after an error the reader stays failed.
#include <cstdint>
#include <cstdlib>

#include "msgraphs/drivers/pcap/pcap_reader.hpp"

using namespace msgraphs;
using namespace msgraphs::drivers::pcap;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  auto reader = PcapBufferReader::Open({data, size});
  if (!reader) return 0;
  PcapRecord record;
  PcapUdpCounters counters;
  for (int guard = 0; guard < 100000; ++guard) {
    auto next = reader->Next(record);
    if (!next) {
      if (reader->Next(record).has_value()) std::abort();  // errors are sticky
      break;
    }
    if (!*next) break;
    if (record.data.data() < data || record.data.data() + record.data.size() > data + size) std::abort();
    auto d = ExtractUdp(reader->header(), record, counters);
    if (d && (d->payload.data() < record.data.data() ||
              d->payload.data() + d->payload.size() > record.data.data() + record.data.size())) {
      std::abort();
    }
  }
  if (counters.udp_datagrams + counters.other_traffic + counters.malformed_frames != counters.records) std::abort();
  return 0;
}
