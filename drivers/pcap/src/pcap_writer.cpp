// SPDX-License-Identifier: MIT
#include "msgraphs/drivers/pcap/pcap_writer.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace msgraphs::drivers::pcap {
namespace {
constexpr std::size_t kBufferBytes = 256u << 10;
constexpr std::size_t kFrameBytes = 65535 + kEthernetIpv4UdpHeaderBytes;
}  // namespace

Expected<PcapFileWriter> PcapFileWriter::Create(const char* path, TimestampPrecision precision,
                                                std::uint32_t snaplen) {
  if (snaplen < 64 || snaplen > kMaxRecordBytes) {
    return Error{Errc::kInvalidArgument, "pcap: snaplen must be 64..262144"};
  }
  const int fd = ::open(path, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) return Error{Errc::kIo, "pcap: cannot create file", errno};
  PcapFileWriter writer(fd, precision, snaplen);
  std::uint8_t header[kGlobalHeaderBytes];
  WriteGlobalHeader(std::span<std::uint8_t, kGlobalHeaderBytes>(header), precision, snaplen,
                    LinkType::kEthernet);
  if (Status s = writer.Append(header); !s) return s.error();
  return writer;
}

PcapFileWriter::PcapFileWriter(int fd, TimestampPrecision precision, std::uint32_t snaplen)
    : fd_(fd),
      precision_(precision),
      snaplen_(snaplen),
      buffer_(std::make_unique<std::uint8_t[]>(kBufferBytes)),
      frame_(std::make_unique<std::uint8_t[]>(kFrameBytes)) {}

PcapFileWriter::PcapFileWriter(PcapFileWriter&& other) noexcept
    : fd_(other.fd_),
      precision_(other.precision_),
      snaplen_(other.snaplen_),
      buffer_(std::move(other.buffer_)),
      frame_(std::move(other.frame_)),
      used_(other.used_),
      records_(other.records_) {
  other.fd_ = -1;
}

PcapFileWriter::~PcapFileWriter() { static_cast<void>(Close()); }

Status PcapFileWriter::Append(std::span<const std::uint8_t> bytes) {
  if (fd_ < 0) return Error{Errc::kInvalidArgument, "pcap: writer is closed"};
  if (used_ + bytes.size() > kBufferBytes) {
    if (Status s = Flush(); !s) return s;
  }
  if (bytes.size() > kBufferBytes) return Error{Errc::kCapacityExceeded, "pcap: record too large"};
  std::memcpy(buffer_.get() + used_, bytes.data(), bytes.size());
  used_ += bytes.size();
  return Ok();
}

Status PcapFileWriter::WriteFrame(UnixTime timestamp, std::span<const std::uint8_t> frame) {
  const auto original = static_cast<std::uint32_t>(frame.size());
  const std::uint32_t captured = original < snaplen_ ? original : snaplen_;
  std::uint8_t header[kRecordHeaderBytes];
  WriteRecordHeader(std::span<std::uint8_t, kRecordHeaderBytes>(header), timestamp, precision_,
                    captured, original);
  if (Status s = Append(header); !s) return s;
  if (Status s = Append(frame.first(captured)); !s) return s;
  ++records_;
  return Ok();
}

Status PcapFileWriter::WriteUdp(UnixTime timestamp, const Ipv4Endpoint& source,
                                const Ipv4Endpoint& destination,
                                std::span<const std::uint8_t> payload) {
  auto length = BuildUdpFrame(source, destination, payload, {frame_.get(), kFrameBytes});
  if (!length) return length.error();
  return WriteFrame(timestamp, {frame_.get(), *length});
}

Status PcapFileWriter::Flush() {
  std::size_t done = 0;
  while (done < used_) {
    const ssize_t n = ::write(fd_, buffer_.get() + done, used_ - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      return Error{Errc::kIo, "pcap: write failed", errno};
    }
    done += static_cast<std::size_t>(n);
  }
  used_ = 0;
  return Ok();
}

Status PcapFileWriter::Close() {
  if (fd_ < 0) return Ok();
  Status flushed = Flush();
  const int rc = ::close(fd_);
  fd_ = -1;
  if (!flushed) return flushed;
  if (rc != 0) return Error{Errc::kIo, "pcap: close failed", errno};
  return Ok();
}

}  // namespace msgraphs::drivers::pcap
