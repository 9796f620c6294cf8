// SPDX-License-Identifier: MIT
#include "msgraphs/drivers/pcap/pcap_format.hpp"

#include "msgraphs/base/byte_order.hpp"

namespace msgraphs::drivers::pcap {
namespace {

std::uint32_t Swap32(std::uint32_t v) {
  return (v >> 24) | ((v >> 8) & 0xFF00u) | ((v << 8) & 0xFF0000u) | (v << 24);
}
// Files are written in the writer's byte order; the magic number says whether it was ours.
std::uint32_t ReadU32(const std::uint8_t* p, bool swapped) {
  const std::uint32_t le = ReadU32Le(p);
  return swapped ? Swap32(le) : le;
}
std::uint16_t ReadU16(const std::uint8_t* p, bool swapped) {
  return swapped ? static_cast<std::uint16_t>((p[0] << 8) | p[1]) : ReadU16Le(p);
}

}  // namespace

Expected<GlobalHeader> ParseGlobalHeader(std::span<const std::uint8_t> bytes) {
  if (bytes.size() < kGlobalHeaderBytes) {
    return Error{Errc::kMalformed, "pcap: file shorter than the 24-byte global header"};
  }
  GlobalHeader h;
  const std::uint32_t magic = ReadU32(bytes.data(), false);
  if (magic == kMagicMicroseconds || magic == kMagicNanoseconds) {
    h.swapped = false;
  } else if (Swap32(magic) == kMagicMicroseconds || Swap32(magic) == kMagicNanoseconds) {
    h.swapped = true;
  } else if (magic == 0x0A0D0D0A) {
    return Error{Errc::kUnsupported,
                 "pcap: this is a pcapng file; convert it with editcap -F pcap"};
  } else {
    return Error{Errc::kMalformed, "pcap: bad magic number (not a libpcap file)"};
  }
  const std::uint32_t native = h.swapped ? Swap32(magic) : magic;
  h.precision = native == kMagicNanoseconds ? TimestampPrecision::kNanoseconds
                                            : TimestampPrecision::kMicroseconds;
  h.version_major = ReadU16(bytes.data() + 4, h.swapped);
  h.version_minor = ReadU16(bytes.data() + 6, h.swapped);
  if (h.version_major != 2) return Error{Errc::kMalformed, "pcap: major version is not 2"};
  h.snaplen = ReadU32(bytes.data() + 16, h.swapped);
  // The upper 16 bits of the link-type field carry FCS flags in newer files; keep the type.
  h.link_type = ReadU32(bytes.data() + 20, h.swapped) & 0xFFFFu;
  return h;
}

Expected<RecordHeader> ParseRecordHeader(std::span<const std::uint8_t> bytes,
                                         const GlobalHeader& header) {
  if (bytes.size() < kRecordHeaderBytes) {
    return Error{Errc::kMalformed, "pcap: truncated record header"};
  }
  const std::uint32_t seconds = ReadU32(bytes.data(), header.swapped);
  const std::uint32_t fraction = ReadU32(bytes.data() + 4, header.swapped);
  RecordHeader r;
  r.captured_bytes = ReadU32(bytes.data() + 8, header.swapped);
  r.original_bytes = ReadU32(bytes.data() + 12, header.swapped);
  const bool nanos = header.precision == TimestampPrecision::kNanoseconds;
  if (fraction >= (nanos ? 1'000'000'000u : 1'000'000u)) {
    return Error{Errc::kMalformed, "pcap: record sub-second field out of range"};
  }
  if (r.captured_bytes > kMaxRecordBytes) {
    return Error{Errc::kMalformed, "pcap: record length beyond 262144 bytes (corrupt file)"};
  }
  if (r.captured_bytes > r.original_bytes) {
    return Error{Errc::kMalformed, "pcap: captured length exceeds original length"};
  }
  const std::int64_t ns = static_cast<std::int64_t>(seconds) * 1'000'000'000 +
                          static_cast<std::int64_t>(fraction) * (nanos ? 1 : 1000);
  r.timestamp = UnixTime::FromNanoseconds(ns);
  return r;
}

void WriteGlobalHeader(std::span<std::uint8_t, kGlobalHeaderBytes> out,
                       TimestampPrecision precision,
                       std::uint32_t snaplen,
                       LinkType link_type) {
  WriteU32Le(out.data(), precision == TimestampPrecision::kNanoseconds ? kMagicNanoseconds
                                                                       : kMagicMicroseconds);
  WriteU16Le(out.data() + 4, 2);
  WriteU16Le(out.data() + 6, 4);
  WriteU32Le(out.data() + 8, 0);   // thiszone
  WriteU32Le(out.data() + 12, 0);  // sigfigs
  WriteU32Le(out.data() + 16, snaplen);
  WriteU32Le(out.data() + 20, static_cast<std::uint32_t>(link_type));
}

void WriteRecordHeader(std::span<std::uint8_t, kRecordHeaderBytes> out,
                       UnixTime timestamp,
                       TimestampPrecision precision,
                       std::uint32_t captured_bytes,
                       std::uint32_t original_bytes) {
  std::int64_t ns = timestamp.nanoseconds_since_epoch();
  if (ns < 0) ns = 0;  // pcap has no times before 1970
  const auto seconds = static_cast<std::uint32_t>(ns / 1'000'000'000);
  const auto sub_ns = static_cast<std::uint32_t>(ns % 1'000'000'000);
  WriteU32Le(out.data(), seconds);
  WriteU32Le(out.data() + 4,
             precision == TimestampPrecision::kNanoseconds ? sub_ns : sub_ns / 1000u);
  WriteU32Le(out.data() + 8, captured_bytes);
  WriteU32Le(out.data() + 12, original_bytes);
}

}  // namespace msgraphs::drivers::pcap
