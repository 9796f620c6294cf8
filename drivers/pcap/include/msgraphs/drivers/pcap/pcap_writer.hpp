// SPDX-License-Identifier: MIT
// Writer of classic pcap files (Ethernet link type) that tcpdump, Wireshark and VeloView read.
// Buffered in one fixed buffer allocated at Create; writes never allocate.
#pragma once

#include <cstdint>
#include <memory>
#include <span>

#include "msgraphs/base/expected.hpp"
#include "msgraphs/drivers/pcap/pcap_format.hpp"
#include "msgraphs/drivers/pcap/udp_frame.hpp"

namespace msgraphs::drivers::pcap {

class PcapFileWriter {
 public:
  /// Creates (truncates) `path`. Snaplen 65535 keeps every UDP datagram whole.
  static Expected<PcapFileWriter> Create(const char* path, TimestampPrecision precision,
                                         std::uint32_t snaplen = 65535);

  /// Appends one Ethernet frame; frames longer than snaplen are cut (original length kept).
  Status WriteFrame(UnixTime timestamp, std::span<const std::uint8_t> frame);
  /// Wraps `payload` in Ethernet/IPv4/UDP headers and appends it.
  Status WriteUdp(UnixTime timestamp, const Ipv4Endpoint& source, const Ipv4Endpoint& destination,
                  std::span<const std::uint8_t> payload);
  Status Flush();
  /// Flushes and closes; the destructor does the same but cannot report errors.
  Status Close();

  std::uint64_t records() const { return records_; }

  PcapFileWriter(PcapFileWriter&& other) noexcept;
  PcapFileWriter& operator=(PcapFileWriter&&) = delete;
  PcapFileWriter(const PcapFileWriter&) = delete;
  ~PcapFileWriter();

 private:
  PcapFileWriter(int fd, TimestampPrecision precision, std::uint32_t snaplen);
  Status Append(std::span<const std::uint8_t> bytes);

  int fd_ = -1;
  TimestampPrecision precision_;
  std::uint32_t snaplen_;
  std::unique_ptr<std::uint8_t[]> buffer_;
  std::unique_ptr<std::uint8_t[]> frame_;
  std::size_t used_ = 0;
  std::uint64_t records_ = 0;
};

}  // namespace msgraphs::drivers::pcap
