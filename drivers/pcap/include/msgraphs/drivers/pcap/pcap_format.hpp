// SPDX-License-Identifier: MIT
// Classic libpcap file format (not pcapng): a 24-byte global header, then records of a 16-byte
// header and the captured bytes. Byte order is whatever the writer's host used; the magic number
// tells which, and whether the sub-second field counts microseconds or nanoseconds.
#pragma once

#include <cstdint>
#include <span>

#include "msgraphs/base/expected.hpp"
#include "msgraphs/base/time.hpp"

namespace msgraphs::drivers::pcap {

inline constexpr std::uint32_t kMagicMicroseconds = 0xA1B2C3D4;
inline constexpr std::uint32_t kMagicNanoseconds = 0xA1B23C4D;
inline constexpr std::size_t kGlobalHeaderBytes = 24;
inline constexpr std::size_t kRecordHeaderBytes = 16;
/// libpcap's own upper bound on a record (MAXIMUM_SNAPLEN); larger lengths mean corruption.
inline constexpr std::uint32_t kMaxRecordBytes = 262144;

enum class LinkType : std::uint32_t {
  kEthernet = 1,
  kRaw = 101,        ///< bare IPv4/IPv6 packets
  kLinuxSll = 113,   ///< "Linux cooked" captures (tcpdump -i any)
};

enum class TimestampPrecision : std::uint8_t { kMicroseconds, kNanoseconds };

struct GlobalHeader {
  bool swapped = false;  ///< file written on a host of the other byte order
  TimestampPrecision precision = TimestampPrecision::kMicroseconds;
  std::uint16_t version_major = 2;
  std::uint16_t version_minor = 4;
  std::uint32_t snaplen = 0;
  std::uint32_t link_type = 1;
};

struct RecordHeader {
  UnixTime timestamp;
  std::uint32_t captured_bytes = 0;
  std::uint32_t original_bytes = 0;
};

/// kMalformed (with a reason) for a bad magic or version; kUnsupported for pcapng.
Expected<GlobalHeader> ParseGlobalHeader(std::span<const std::uint8_t> bytes);
/// kMalformed for a sub-second field out of range or a length beyond kMaxRecordBytes or the
/// original length.
Expected<RecordHeader> ParseRecordHeader(std::span<const std::uint8_t> bytes,
                                         const GlobalHeader& header);

void WriteGlobalHeader(std::span<std::uint8_t, kGlobalHeaderBytes> out, TimestampPrecision precision,
                       std::uint32_t snaplen, LinkType link_type);
void WriteRecordHeader(std::span<std::uint8_t, kRecordHeaderBytes> out, UnixTime timestamp,
                       TimestampPrecision precision, std::uint32_t captured_bytes,
                       std::uint32_t original_bytes);

}  // namespace msgraphs::drivers::pcap
