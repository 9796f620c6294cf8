// SPDX-License-Identifier: MIT
#include "msgraphs/runtime/pipeline/journal.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>

#include "msgraphs/base/byte_order.hpp"
#include "msgraphs/base/crc32.hpp"

namespace msgraphs::runtime {

namespace {

constexpr std::size_t kRecordHeader = 12;
constexpr std::uint32_t kMaxRecordBytes = 64u << 20;  // far above any scan (60,000 points: 480 kB)
constexpr double kTimeStep_s = 4e-6;                  // scan point times: 4 us steps, 262 ms

std::string Header(std::uint16_t robot) {
  return "MSGRAPHS-JOURNAL v1 robot " + std::to_string(robot) + "\n";
}

class Out {
 public:
  explicit Out(std::vector<std::uint8_t>& b) : b_(b) { b_.clear(); }
  void U8(std::uint8_t v) { b_.push_back(v); }
  void U16(std::uint16_t v) {
    U8(static_cast<std::uint8_t>(v));
    U8(static_cast<std::uint8_t>(v >> 8));
  }
  void U32(std::uint32_t v) {
    for (int i = 0; i < 4; ++i) U8(static_cast<std::uint8_t>(v >> (8 * i)));
  }
  void F64(double d) {
    std::uint64_t u;
    std::memcpy(&u, &d, 8);
    for (int i = 0; i < 8; ++i) U8(static_cast<std::uint8_t>(u >> (8 * i)));
  }

 private:
  std::vector<std::uint8_t>& b_;
};

class In {
 public:
  explicit In(std::span<const std::uint8_t> b) : b_(b) {}
  bool Has(std::size_t n) const { return pos_ + n <= b_.size(); }
  bool AtEnd() const { return pos_ == b_.size(); }
  std::uint8_t U8() { return b_[pos_++]; }
  std::uint16_t U16() {
    const std::uint16_t v = ReadU16Le(&b_[pos_]);
    pos_ += 2;
    return v;
  }
  std::uint32_t U32() {
    const std::uint32_t v = ReadU32Le(&b_[pos_]);
    pos_ += 4;
    return v;
  }
  double F64() {
    std::uint64_t u = 0;
    for (int i = 0; i < 8; ++i)
      u |= static_cast<std::uint64_t>(b_[pos_ + static_cast<std::size_t>(i)]) << (8 * i);
    pos_ += 8;
    double d;
    std::memcpy(&d, &u, 8);
    return d;
  }
  std::span<const std::uint8_t> Rest() const { return b_.subspan(pos_); }

 private:
  std::span<const std::uint8_t> b_;
  std::size_t pos_ = 0;
};

void PutPose(Out& o, const Eigen::Isometry3d& T) {
  const Eigen::Quaterniond q(T.linear());
  for (int i = 0; i < 3; ++i) o.F64(T.translation()[i]);
  o.F64(q.x());
  o.F64(q.y());
  o.F64(q.z());
  o.F64(q.w());
}

Eigen::Isometry3d GetPose(In& in) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  const double x = in.F64(), y = in.F64(), z = in.F64();
  const double qx = in.F64(), qy = in.F64(), qz = in.F64(), qw = in.F64();
  T.linear() = Eigen::Quaterniond(qw, qx, qy, qz).normalized().toRotationMatrix();
  T.translation() << x, y, z;
  return T;
}

Status IoError(const char* what) { return Error{Errc::kIo, what, errno}; }

// Whether `path` is absent or a regular file: a FIFO, device or link planted under a journal's
// name would block or redirect the reader.
bool AbsentOrRegular(const std::string& path) {
  struct stat st {};
  if (::lstat(path.c_str(), &st) != 0) return errno == ENOENT;
  return S_ISREG(st.st_mode);
}

// Whether every f64 of a record's payload is finite: `bytes` all f64s (lead 0), or blocks of a
// `lead`-byte id followed by 13 f64s (priors: plane u32, normal, d, covariance). A NaN in the
// file is refused like a bad CRC: replay stops there, as it does at any record it cannot use.
bool AllFinite(std::span<const std::uint8_t> bytes, std::size_t lead = 0) {
  const std::size_t stride = lead == 0 ? 8 : lead + 104;
  for (std::size_t at = 0; at + stride <= bytes.size(); at += stride) {
    for (std::size_t f = at + lead; f + 8 <= at + stride; f += 8) {
      double d;
      std::memcpy(&d, bytes.data() + f, 8);
      if (!std::isfinite(d)) return false;
    }
  }
  return true;
}

}  // namespace

Expected<JournalWriter> JournalWriter::Open(const std::string& path,
                                            std::uint16_t robot,
                                            std::uint64_t valid_bytes) {
  // O_NOFOLLOW: a link planted in the checkpoint folder must not make the node write elsewhere.
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC | O_NOFOLLOW, 0644);
  if (fd < 0) return IoError("journal: cannot open for writing").error();
  JournalWriter w(fd, 0);
  if (valid_bytes == 0) {
    const std::string header = Header(robot);
    if (::ftruncate(fd, 0) != 0 ||
        ::write(fd, header.data(), header.size()) != static_cast<ssize_t>(header.size()))
      return IoError("journal: cannot write the header").error();
    w.bytes_ = header.size();
  } else {
    // Cut a torn tail, append after the last good record. Synced: records appended after the
    // cut must never reach the disk behind the torn bytes they replace.
    struct stat st {};
    if (::fstat(fd, &st) != 0) return IoError("journal: cannot stat").error();
    if (static_cast<std::uint64_t>(st.st_size) != valid_bytes &&
        (::ftruncate(fd, static_cast<off_t>(valid_bytes)) != 0 || ::fdatasync(fd) != 0))
      return IoError("journal: cannot truncate").error();
    w.bytes_ = valid_bytes;
  }
  if (::lseek(fd, static_cast<off_t>(w.bytes_), SEEK_SET) < 0)
    return IoError("journal: cannot seek").error();
  return w;
}

JournalWriter::JournalWriter(JournalWriter&& other) noexcept
    : fd_(other.fd_),
      bytes_(other.bytes_),
      records_(other.records_),
      messages_(other.messages_),
      buffer_(std::move(other.buffer_)),
      record_(std::move(other.record_)) {
  other.fd_ = -1;
}

JournalWriter::~JournalWriter() {
  if (fd_ >= 0) ::close(fd_);
}

Status JournalWriter::Write(JournalRecord type, std::span<const std::uint8_t> payload) {
  // Header and payload in one buffer and one write(): a killed process leaves whole records.
  record_.resize(kRecordHeader + payload.size());
  if (!payload.empty())  // an empty span's data() may be null, which memcpy may not take
    std::memcpy(record_.data() + kRecordHeader, payload.data(), payload.size());
  // The CRC covers the type and the payload: put the type just before the payload (in the CRC
  // field, overwritten next) to checksum them in one pass.
  record_[kRecordHeader - 1] = static_cast<std::uint8_t>(type);
  const std::uint32_t crc = Crc32(std::span(record_).subspan(kRecordHeader - 1));
  record_[0] = static_cast<std::uint8_t>(type);
  record_[1] = record_[2] = record_[3] = 0;
  WriteU32Le(&record_[4], static_cast<std::uint32_t>(payload.size()));
  WriteU32Le(&record_[8], crc);
  const std::vector<std::uint8_t>& record = record_;
  std::size_t done = 0;
  while (done < record.size()) {
    const ssize_t n = ::write(fd_, record.data() + done, record.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return IoError("journal: write failed (disk full?)");
    done += static_cast<std::size_t>(n);
  }
  bytes_ += record.size();
  ++records_;
  return Ok();
}

Status JournalWriter::Odometry(double stamp_s, const Eigen::Isometry3d& T) {
  Out o(buffer_);
  o.F64(stamp_s);
  PutPose(o, T);
  return Write(JournalRecord::kOdometry, buffer_);
}

Status JournalWriter::Scan(std::span<const Eigen::Vector3f> points,
                           std::span<const float> times,
                           double start_s,
                           double end_s,
                           float max_range_m) {
  Out o(buffer_);
  o.F64(start_s);
  o.F64(end_s);
  const std::size_t count_at = buffer_.size();
  o.U32(0);
  // Points beyond the mapper's range are dropped by its first step anyway: only those it uses
  // are kept, and they fit 16 bits in millimetres.
  const float limit = std::min(max_range_m + 0.01f, 32.7f);
  std::uint32_t kept = 0;
  for (std::size_t i = 0; i < points.size() && i < times.size(); ++i) {
    const Eigen::Vector3f& p = points[i];
    if (!p.allFinite() || !(p.norm() <= limit)) continue;
    for (int k = 0; k < 3; ++k)
      o.U16(static_cast<std::uint16_t>(static_cast<std::int16_t>(std::lround(p[k] * 1000.0f))));
    const double t = std::clamp(static_cast<double>(times[i]) / kTimeStep_s, 0.0, 65535.0);
    o.U16(static_cast<std::uint16_t>(std::lround(t)));
    ++kept;
  }
  WriteU32Le(&buffer_[count_at], kept);
  return Write(JournalRecord::kScan, buffer_);
}

Status JournalWriter::Priors(std::span<const core::PlanePrior> priors) {
  Out o(buffer_);
  o.U32(static_cast<std::uint32_t>(priors.size()));
  for (const core::PlanePrior& p : priors) {
    o.U32(p.plane);
    for (int k = 0; k < 3; ++k) o.F64(p.normal[k]);
    o.F64(p.d);
    for (int k = 0; k < 9; ++k) o.F64(p.covariance(k / 3, k % 3));
  }
  return Write(JournalRecord::kPriors, buffer_);
}

Status JournalWriter::Finish() { return Write(JournalRecord::kFinish, {}); }

Status JournalWriter::Motion(double end_s, const Eigen::Isometry3d& T_last_new, bool tracked) {
  Out o(buffer_);
  o.F64(end_s);
  PutPose(o, T_last_new);
  o.U8(tracked ? 1 : 0);
  return Write(JournalRecord::kMotion, buffer_);
}

Status JournalWriter::Message(core::CollabMessageType type, std::span<const std::uint8_t> bytes) {
  Out o(buffer_);
  o.U8(static_cast<std::uint8_t>(type));
  buffer_.insert(buffer_.end(), bytes.begin(), bytes.end());
  Status s = Write(JournalRecord::kMessage, buffer_);
  if (s) ++messages_;
  return s;
}

void JournalWriter::TakeBuffersFrom(JournalWriter& other) {
  buffer_.swap(other.buffer_);
  record_.swap(other.record_);
}

Status JournalWriter::Continues(std::uint64_t generation, std::uint64_t bytes) {
  Out o(buffer_);
  o.U32(static_cast<std::uint32_t>(generation));
  o.U32(static_cast<std::uint32_t>(generation >> 32));
  o.U32(static_cast<std::uint32_t>(bytes));
  o.U32(static_cast<std::uint32_t>(bytes >> 32));
  return Write(JournalRecord::kContinues, buffer_);
}

int JournalWriter::DuplicateDescriptor() const { return ::fcntl(fd_, F_DUPFD_CLOEXEC, 0); }

Status ReadContinuation(const std::string& path, std::uint16_t robot, bool& found,
                        std::uint64_t& generation, std::uint64_t& bytes) {
  found = false;
  if (!AbsentOrRegular(path)) return Error{Errc::kInvalidArgument, "journal: not a regular file"};
  std::ifstream file(path, std::ios::binary);
  if (!file) return Ok();
  const std::string expected = Header(robot);
  std::string header(expected.size(), '\0');
  std::uint8_t record[kRecordHeader + 16];
  if (!file.read(header.data(), static_cast<std::streamsize>(header.size())) || header != expected ||
      !file.read(reinterpret_cast<char*>(record), sizeof record))
    return Ok();
  if (record[0] != static_cast<std::uint8_t>(JournalRecord::kContinues) ||
      ReadU32Le(&record[4]) != 16)
    return Ok();
  std::uint8_t covered[17];
  covered[0] = record[0];
  std::memcpy(covered + 1, record + kRecordHeader, 16);
  if (Crc32(covered) != ReadU32Le(&record[8])) return Ok();
  const std::uint8_t* p = record + kRecordHeader;
  generation = ReadU32Le(p) | static_cast<std::uint64_t>(ReadU32Le(p + 4)) << 32;
  bytes = ReadU32Le(p + 8) | static_cast<std::uint64_t>(ReadU32Le(p + 12)) << 32;
  found = true;
  return Ok();
}

Status JournalWriter::Sync() {
  if (::fdatasync(fd_) != 0) return IoError("journal: fsync failed");
  return Ok();
}

Expected<JournalReplay> ReplayJournal(const std::string& path,
                                      std::uint16_t robot,
                                      JournalSink& sink) {
  if (!AbsentOrRegular(path)) return Error{Errc::kInvalidArgument, "journal: not a regular file"};
  std::ifstream file(path, std::ios::binary);
  if (!file) return JournalReplay{};  // no journal yet: a fresh start
  return ReplayJournal(file, robot, sink);
}

Expected<JournalReplay> ReplayJournal(std::istream& file, std::uint16_t robot, JournalSink& sink) {
  JournalReplay r;
  const std::string expected = Header(robot);
  std::string header(expected.size(), '\0');
  if (!file.read(header.data(), static_cast<std::streamsize>(header.size())) ||
      header != expected) {
    if (header.rfind("MSGRAPHS-JOURNAL", 0) == 0)
      return Error{Errc::kInvalidConfig, "checkpoint journal belongs to another robot id"};
    r.stopped = "no journal header";
    return r;
  }
  r.valid_bytes = expected.size();
  std::vector<std::uint8_t> payload, covered;
  std::vector<Eigen::Vector3f> points;
  std::vector<float> times;
  std::vector<core::PlanePrior> priors;
  for (;;) {
    std::uint8_t head[kRecordHeader];
    if (!file.read(reinterpret_cast<char*>(head), kRecordHeader)) {
      if (file.gcount() != 0) r.stopped = "torn record header at the end";
      break;
    }
    const auto type = static_cast<JournalRecord>(head[0]);
    const std::uint32_t length = ReadU32Le(&head[4]);
    if (length > kMaxRecordBytes) {
      r.stopped = "record length beyond any record";
      break;
    }
    payload.resize(length);
    if (!file.read(reinterpret_cast<char*>(payload.data()), length)) {
      r.stopped = "torn record at the end";
      break;
    }
    covered.assign(1, head[0]);
    covered.insert(covered.end(), payload.begin(), payload.end());
    if (Crc32(covered) != ReadU32Le(&head[8])) {
      r.stopped = "record CRC mismatch";
      break;
    }
    In in(payload);
    bool ok = true;
    switch (type) {
      case JournalRecord::kOdometry: {
        if (!(ok = length == 64 && AllFinite(payload))) break;
        const double t = in.F64();
        sink.OnOdometry(t, GetPose(in));
        r.last_odometry_s = t;
        ++r.odometry;
        break;
      }
      case JournalRecord::kScan: {
        if (!(ok = in.Has(20))) break;
        const double start = in.F64(), end = in.F64();
        const std::uint32_t n = in.U32();
        if (!(ok = in.Rest().size() == static_cast<std::size_t>(n) * 8 && std::isfinite(start) &&
                   std::isfinite(end) && start <= end))
          break;
        points.resize(n);
        times.resize(n);
        for (std::uint32_t i = 0; i < n; ++i) {
          for (int k = 0; k < 3; ++k)
            points[i][k] = static_cast<float>(static_cast<std::int16_t>(in.U16())) * 1e-3f;
          times[i] = static_cast<float>(in.U16() * kTimeStep_s);
        }
        sink.OnScan(points, times, start, end);
        r.last_scan_end_s = end;
        ++r.scans;
        break;
      }
      case JournalRecord::kPriors: {
        if (!(ok = in.Has(4))) break;
        const std::uint32_t n = in.U32();
        if (!(ok = in.Rest().size() == static_cast<std::size_t>(n) * 108 &&
                   AllFinite(in.Rest(), 4)))
          break;
        priors.resize(n);
        for (core::PlanePrior& p : priors) {
          p.plane = in.U32();
          for (int k = 0; k < 3; ++k) p.normal[k] = in.F64();
          p.d = in.F64();
          for (int k = 0; k < 9; ++k) p.covariance(k / 3, k % 3) = in.F64();
        }
        sink.OnPriors(priors);
        ++r.priors;
        break;
      }
      case JournalRecord::kFinish:
        sink.OnFinish();
        ++r.finishes;
        break;
      case JournalRecord::kMessage: {
        if (!(ok = in.Has(1))) break;
        const std::uint8_t t = in.U8();
        if (!(ok = t < core::kCollabMessageTypes)) break;
        sink.OnMessage(static_cast<core::CollabMessageType>(t), in.Rest());
        ++r.messages;
        break;
      }
      case JournalRecord::kMotion: {
        if (!(ok = length == 65 && AllFinite(std::span(payload).first(64)))) break;
        const double end = in.F64();
        const Eigen::Isometry3d T = GetPose(in);
        const std::uint8_t tracked = in.U8();
        if (!(ok = tracked <= 1 && std::isfinite(end))) break;
        sink.OnMotion(end, T, tracked == 1);
        ++r.motions;
        break;
      }
      case JournalRecord::kContinues: {
        // Only as the first record (ReadContinuation reads it there; elsewhere it is no record
        // this writer makes).
        if (!(ok = length == 16 && r.records == 0)) break;
        const std::uint64_t g_lo = in.U32(), g_hi = in.U32();
        const std::uint64_t b_lo = in.U32(), b_hi = in.U32();
        r.continues = true;
        r.continues_generation = g_lo | g_hi << 32;
        r.continues_bytes = b_lo | b_hi << 32;
        break;
      }
      default:
        ok = false;
    }
    if (!ok) {
      r.stopped = "record of unknown type, wrong size or numbers that are not finite";
      break;
    }
    ++r.records;
    r.valid_bytes += kRecordHeader + length;
  }
  return r;
}

}  // namespace msgraphs::runtime
