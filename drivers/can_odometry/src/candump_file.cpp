// SPDX-License-Identifier: MIT
#include "msgraphs/drivers/can_odometry/candump_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace msgraphs::drivers::can_odometry {
namespace {
constexpr std::size_t kReadBufferBytes = 64u << 10;
constexpr std::size_t kMaxLineBytes = 1024;  // a CAN FD line is at most ~180 characters
constexpr std::size_t kWriteBufferBytes = 64u << 10;
}  // namespace

Expected<CandumpFileReader> CandumpFileReader::Open(const char* path) {
  const int fd = ::open(path, O_RDONLY | O_CLOEXEC);
  if (fd < 0) return Error{Errc::kIo, "candump: cannot open file", errno};
  return CandumpFileReader(fd);
}

CandumpFileReader::CandumpFileReader(int fd)
    : fd_(fd), buffer_(std::make_unique<char[]>(kReadBufferBytes)) {}

CandumpFileReader::CandumpFileReader(CandumpFileReader&& other) noexcept
    : fd_(other.fd_),
      buffer_(std::move(other.buffer_)),
      begin_(other.begin_),
      end_(other.end_),
      eof_(other.eof_),
      stats_(other.stats_),
      last_reason_(other.last_reason_),
      last_malformed_line_(other.last_malformed_line_) {
  other.fd_ = -1;
}

CandumpFileReader::~CandumpFileReader() {
  if (fd_ >= 0) ::close(fd_);
}

// Returns the next line without its newline; an over-long line is returned truncated to
// kMaxLineBytes + 1 so the caller can reject it.
Expected<bool> CandumpFileReader::ReadLine(std::string_view& line) {
  bool overlong = false;
  for (;;) {
    const char* start = buffer_.get() + begin_;
    const void* nl = std::memchr(start, '\n', end_ - begin_);
    if (nl != nullptr) {
      const auto length = static_cast<std::size_t>(static_cast<const char*>(nl) - start);
      line = overlong ? std::string_view(start, 0) : std::string_view(start, length);
      begin_ += length + 1;
      if (overlong) line = std::string_view(buffer_.get(), kMaxLineBytes + 1);
      return true;
    }
    if (eof_) {
      if (begin_ == end_) return false;
      line = std::string_view(start, end_ - begin_);  // last line without newline
      begin_ = end_;
      if (overlong) line = std::string_view(buffer_.get(), kMaxLineBytes + 1);
      return true;
    }
    if (end_ - begin_ > kMaxLineBytes) {
      overlong = true;  // discard what we have and keep looking for the newline
      begin_ = end_;
    }
    if (begin_ > 0) {
      std::memmove(buffer_.get(), buffer_.get() + begin_, end_ - begin_);
      end_ -= begin_;
      begin_ = 0;
    }
    const ssize_t got = ::read(fd_, buffer_.get() + end_, kReadBufferBytes - end_);
    if (got < 0) {
      if (errno == EINTR) continue;
      return Error{Errc::kIo, "candump: read failed", errno};
    }
    if (got == 0) eof_ = true;
    end_ += static_cast<std::size_t>(got);
  }
}

Expected<bool> CandumpFileReader::Next(CandumpLine& out) {
  for (;;) {
    std::string_view text;
    auto got = ReadLine(text);
    if (!got) return got.error();
    if (!*got) return false;
    ++stats_.lines;
    if (text.size() > kMaxLineBytes) {
      ++stats_.malformed;
      last_reason_ = "candump: line longer than 1024 characters";
      last_malformed_line_ = stats_.lines;
      continue;
    }
    auto parsed = ParseCandumpLine(text);
    if (!parsed) {
      ++stats_.malformed;
      last_reason_ = parsed.error().detail;
      last_malformed_line_ = stats_.lines;
      continue;
    }
    switch (parsed->kind) {
      case CandumpLine::Kind::kComment: ++stats_.comments; continue;
      case CandumpLine::Kind::kCanFd: ++stats_.can_fd; continue;
      case CandumpLine::Kind::kCanXl: ++stats_.can_xl; continue;
      case CandumpLine::Kind::kFrame: break;
    }
    ++stats_.frames;
    out = *parsed;
    return true;
  }
}

Expected<CandumpFileWriter> CandumpFileWriter::Create(const char* path, CandumpPrecision precision) {
  const int fd = ::open(path, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) return Error{Errc::kIo, "candump: cannot create file", errno};
  return CandumpFileWriter(fd, precision);
}

CandumpFileWriter::CandumpFileWriter(int fd, CandumpPrecision precision)
    : fd_(fd), precision_(precision), buffer_(std::make_unique<char[]>(kWriteBufferBytes)) {}

CandumpFileWriter::CandumpFileWriter(CandumpFileWriter&& other) noexcept
    : fd_(other.fd_),
      precision_(other.precision_),
      buffer_(std::move(other.buffer_)),
      used_(other.used_),
      frames_(other.frames_) {
  other.fd_ = -1;
}

CandumpFileWriter::~CandumpFileWriter() { static_cast<void>(Close()); }

Status CandumpFileWriter::Write(UnixTime stamp, std::string_view interface, const CanFrame& frame) {
  if (fd_ < 0) return Error{Errc::kInvalidArgument, "candump: writer is closed"};
  if (kWriteBufferBytes - used_ < kMaxCandumpLine) {
    if (Status s = Flush(); !s) return s;
  }
  auto n = FormatCandumpLine(stamp, interface, frame, precision_,
                             {buffer_.get() + used_, kWriteBufferBytes - used_});
  if (!n) return n.error();
  used_ += *n;
  ++frames_;
  return Ok();
}

Status CandumpFileWriter::Flush() {
  std::size_t done = 0;
  while (done < used_) {
    const ssize_t n = ::write(fd_, buffer_.get() + done, used_ - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      return Error{Errc::kIo, "candump: write failed", errno};
    }
    done += static_cast<std::size_t>(n);
  }
  used_ = 0;
  return Ok();
}

Status CandumpFileWriter::Close() {
  if (fd_ < 0) return Ok();
  Status flushed = Flush();
  const int rc = ::close(fd_);
  fd_ = -1;
  if (!flushed) return flushed;
  if (rc != 0) return Error{Errc::kIo, "candump: close failed", errno};
  return Ok();
}

}  // namespace msgraphs::drivers::can_odometry
