// SPDX-License-Identifier: MIT
#include "msgraphs/drivers/pcap/pcap_reader.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace msgraphs::drivers::pcap {
namespace {
constexpr std::size_t kFileBufferBytes = kMaxRecordBytes + kRecordHeaderBytes + (64u << 10);
}  // namespace

Expected<PcapBufferReader> PcapBufferReader::Open(std::span<const std::uint8_t> bytes) {
  auto header = ParseGlobalHeader(bytes);
  if (!header) return header.error();
  return PcapBufferReader(bytes, *header);
}

Expected<bool> PcapBufferReader::Next(PcapRecord& record) {
  if (failed_) return error_;
  if (offset_ == bytes_.size()) return false;
  auto fail = [&](Error e) -> Expected<bool> {
    failed_ = true;
    error_ = e;
    return e;
  };
  if (bytes_.size() - offset_ < kRecordHeaderBytes) {
    return fail({Errc::kMalformed, "pcap: file ends inside a record header (truncated)"});
  }
  auto rh = ParseRecordHeader(bytes_.subspan(offset_, kRecordHeaderBytes), header_);
  if (!rh) return fail(rh.error());
  offset_ += kRecordHeaderBytes;
  if (bytes_.size() - offset_ < rh->captured_bytes) {
    return fail({Errc::kMalformed, "pcap: file ends inside a record (truncated)"});
  }
  record.header = *rh;
  record.data = bytes_.subspan(offset_, rh->captured_bytes);
  offset_ += rh->captured_bytes;
  ++records_;
  return true;
}

Expected<PcapFileReader> PcapFileReader::Open(const char* path) {
  const int fd = ::open(path, O_RDONLY | O_CLOEXEC);
  if (fd < 0) return Error{Errc::kIo, "pcap: cannot open file", errno};
  PcapFileReader reader(fd);
  auto have = reader.Fill(kGlobalHeaderBytes);
  if (!have) return have.error();
  auto header = ParseGlobalHeader({reader.buffer_.get() + reader.begin_, *have});
  if (!header) return header.error();
  reader.header_ = *header;
  reader.begin_ += kGlobalHeaderBytes;
  return reader;
}

PcapFileReader::PcapFileReader(int fd)
    : fd_(fd), buffer_(std::make_unique<std::uint8_t[]>(kFileBufferBytes)) {}

PcapFileReader::PcapFileReader(PcapFileReader&& other) noexcept
    : fd_(other.fd_),
      buffer_(std::move(other.buffer_)),
      begin_(other.begin_),
      end_(other.end_),
      header_(other.header_),
      records_(other.records_),
      bytes_read_(other.bytes_read_),
      failed_(other.failed_),
      error_(other.error_) {
  other.fd_ = -1;
}

PcapFileReader::~PcapFileReader() {
  if (fd_ >= 0) ::close(fd_);
}

Expected<std::size_t> PcapFileReader::Fill(std::size_t n) {
  if (end_ - begin_ >= n) return end_ - begin_;
  if (begin_ > 0) {
    std::memmove(buffer_.get(), buffer_.get() + begin_, end_ - begin_);
    end_ -= begin_;
    begin_ = 0;
  }
  while (end_ < n) {
    const ssize_t got = ::read(fd_, buffer_.get() + end_, kFileBufferBytes - end_);
    if (got < 0) {
      if (errno == EINTR) continue;
      return Error{Errc::kIo, "pcap: read failed", errno};
    }
    if (got == 0) break;  // end of file
    end_ += static_cast<std::size_t>(got);
    bytes_read_ += static_cast<std::uint64_t>(got);
  }
  return end_ - begin_;
}

Expected<bool> PcapFileReader::Next(PcapRecord& record) {
  if (failed_) return error_;
  auto fail = [&](Error e) -> Expected<bool> {
    failed_ = true;
    error_ = e;
    return e;
  };
  auto have = Fill(kRecordHeaderBytes);
  if (!have) return fail(have.error());
  if (*have == 0) return false;
  if (*have < kRecordHeaderBytes) {
    return fail({Errc::kMalformed, "pcap: file ends inside a record header (truncated)"});
  }
  auto rh = ParseRecordHeader({buffer_.get() + begin_, kRecordHeaderBytes}, header_);
  if (!rh) return fail(rh.error());
  have = Fill(kRecordHeaderBytes + rh->captured_bytes);
  if (!have) return fail(have.error());
  if (*have < kRecordHeaderBytes + rh->captured_bytes) {
    return fail({Errc::kMalformed, "pcap: file ends inside a record (truncated)"});
  }
  record.header = *rh;
  record.data = {buffer_.get() + begin_ + kRecordHeaderBytes, rh->captured_bytes};
  begin_ += kRecordHeaderBytes + rh->captured_bytes;
  ++records_;
  return true;
}

Expected<UdpDatagram> ExtractUdp(const GlobalHeader& header, const PcapRecord& record,
                                 PcapUdpCounters& counters) {
  ++counters.records;
  auto datagram = ParseUdpFrame(header.link_type, record.data);
  if (!datagram) {
    if (datagram.error().code == Errc::kUnsupported) {
      ++counters.other_traffic;
    } else {
      ++counters.malformed_frames;
    }
    return datagram.error();
  }
  ++counters.udp_datagrams;
  if (datagram->payload_truncated) ++counters.truncated_payloads;
  return datagram;
}

}  // namespace msgraphs::drivers::pcap
