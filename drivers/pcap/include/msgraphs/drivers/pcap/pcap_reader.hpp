// SPDX-License-Identifier: MIT
// Readers of classic pcap files. We parse the format ourselves instead of linking Debian's
// libpcap (docs/drivers.md): the parser is pure and fuzzable from bytes, allocation-free per
// record, identical on the arm64 payload without another sysroot package, and it reports a
// truncated or corrupt file precisely while keeping every record before the damage.
//
// Both readers deliver records until the end; at damage they return the error from then on.
#pragma once

#include <cstdint>
#include <memory>
#include <span>

#include "msgraphs/base/expected.hpp"
#include "msgraphs/drivers/pcap/pcap_format.hpp"
#include "msgraphs/drivers/pcap/udp_frame.hpp"

namespace msgraphs::drivers::pcap {

struct PcapRecord {
  RecordHeader header;
  std::span<const std::uint8_t> data;  ///< valid until the reader's next call
};

/// Reader over bytes already in memory (tests, fuzzing, memory-mapped files).
class PcapBufferReader {
 public:
  static Expected<PcapBufferReader> Open(std::span<const std::uint8_t> bytes);

  /// true: `record` holds the next record; false: clean end of file; an error: the file is
  /// truncated or corrupt at this point (records before it were all delivered).
  Expected<bool> Next(PcapRecord& record);

  const GlobalHeader& header() const { return header_; }
  std::uint64_t records() const { return records_; }

 private:
  PcapBufferReader(std::span<const std::uint8_t> bytes, const GlobalHeader& header)
      : bytes_(bytes), header_(header) {}
  std::span<const std::uint8_t> bytes_;
  GlobalHeader header_;
  std::size_t offset_ = kGlobalHeaderBytes;
  std::uint64_t records_ = 0;
  bool failed_ = false;
  Error error_{Errc::kMalformed};
};

/// Streaming reader of a file with one fixed buffer (allocated at Open, sized for the largest
/// legal record), so memory stays bounded for recordings of any length.
class PcapFileReader {
 public:
  static Expected<PcapFileReader> Open(const char* path);

  Expected<bool> Next(PcapRecord& record);

  const GlobalHeader& header() const { return header_; }
  std::uint64_t records() const { return records_; }
  std::uint64_t bytes_read() const { return bytes_read_; }

  PcapFileReader(PcapFileReader&& other) noexcept;
  PcapFileReader& operator=(PcapFileReader&&) = delete;
  PcapFileReader(const PcapFileReader&) = delete;
  ~PcapFileReader();

 private:
  explicit PcapFileReader(int fd);
  // Makes at least `n` bytes available from begin_; returns how many are (less at end of file).
  Expected<std::size_t> Fill(std::size_t n);

  int fd_ = -1;
  std::unique_ptr<std::uint8_t[]> buffer_;
  std::size_t begin_ = 0;
  std::size_t end_ = 0;
  GlobalHeader header_;
  std::uint64_t records_ = 0;
  std::uint64_t bytes_read_ = 0;
  bool failed_ = false;
  Error error_{Errc::kMalformed};
};

/// What reading a capture for UDP payloads skipped, so nothing is dropped silently.
struct PcapUdpCounters {
  std::uint64_t records = 0;
  std::uint64_t udp_datagrams = 0;
  std::uint64_t other_traffic = 0;     ///< ARP, IPv6, TCP, fragments: skipped
  std::uint64_t malformed_frames = 0;  ///< headers that contradict themselves: skipped
  std::uint64_t truncated_payloads = 0;  ///< UDP payload cut by the capture's snaplen
};

/// Parses a record down to its UDP payload and counts what it skips. An error means "skip
/// this record" (it has been counted).
Expected<UdpDatagram> ExtractUdp(const GlobalHeader& header, const PcapRecord& record,
                                 PcapUdpCounters& counters);

}  // namespace msgraphs::drivers::pcap
