// SPDX-License-Identifier: MIT
#include "msgraphs/runtime/pipeline/checkpoint_file.hpp"

#include <cmath>
#include <cstring>

#include "msgraphs/base/byte_order.hpp"
#include "msgraphs/base/crc32.hpp"

namespace msgraphs::runtime {

namespace {

constexpr char kMagic[] = "MSGRAPHS-SNAPSHOT v1\n";
constexpr std::size_t kMagicBytes = sizeof(kMagic) - 1;
static_assert(kMagicBytes == 21);

class Put {
 public:
  explicit Put(std::span<std::uint8_t> out) : out_(out) {}
  void Bytes(const void* p, std::size_t n) {
    std::memcpy(out_.data() + at_, p, n);
    at_ += n;
  }
  void U16(std::uint16_t v) {
    WriteU16Le(out_.data() + at_, v);
    at_ += 2;
  }
  void U32(std::uint32_t v) {
    WriteU32Le(out_.data() + at_, v);
    at_ += 4;
  }
  void U64(std::uint64_t v) {
    U32(static_cast<std::uint32_t>(v));
    U32(static_cast<std::uint32_t>(v >> 32));
  }
  void F64(double d) {
    std::uint64_t u;
    std::memcpy(&u, &d, 8);
    U64(u);
  }
  std::size_t at() const { return at_; }

 private:
  std::span<std::uint8_t> out_;
  std::size_t at_ = 0;
};

class Get {
 public:
  explicit Get(std::span<const std::uint8_t> in) : in_(in) {}
  bool Has(std::size_t n) const { return n <= in_.size() - at_; }
  std::uint8_t U8() { return in_[at_++]; }
  std::uint16_t U16() {
    const std::uint16_t v = ReadU16Le(in_.data() + at_);
    at_ += 2;
    return v;
  }
  std::uint32_t U32() {
    const std::uint32_t v = ReadU32Le(in_.data() + at_);
    at_ += 4;
    return v;
  }
  std::uint64_t U64() {
    const std::uint64_t lo = U32();
    return lo | static_cast<std::uint64_t>(U32()) << 32;
  }
  double F64() {
    const std::uint64_t u = U64();
    double d;
    std::memcpy(&d, &u, 8);
    return d;
  }
  std::span<const std::uint8_t> Take(std::size_t n) {
    const auto s = in_.subspan(at_, n);
    at_ += n;
    return s;
  }
  std::size_t at() const { return at_; }

 private:
  std::span<const std::uint8_t> in_;
  std::size_t at_ = 0;
};

}  // namespace

void WriteCheckpointHead(const CheckpointMeta& meta, std::uint64_t mapper_bytes,
                         std::span<std::uint8_t, kCheckpointHeadBytes> out) {
  Put p(out);
  p.Bytes(kMagic, kMagicBytes);
  p.U16(meta.robot);
  p.U64(meta.generation);
  p.U32(meta.mapper_settings_crc);
  p.F64(meta.last_scan_end_s);
  p.F64(meta.last_odometry_s);
  const Eigen::Quaterniond q(meta.T_odom_last.linear());
  for (int i = 0; i < 3; ++i) p.F64(meta.T_odom_last.translation()[i]);
  p.F64(q.x());
  p.F64(q.y());
  p.F64(q.z());
  p.F64(q.w());
  p.U64(meta.journal_messages);
  p.U64(mapper_bytes);
}

void AppendSessionMessage(core::CollabMessageType type, std::span<const std::uint8_t> bytes,
                          std::vector<std::uint8_t>& out) {
  const std::size_t at = out.size();
  out.resize(at + 5 + bytes.size());
  out[at] = static_cast<std::uint8_t>(type);
  WriteU32Le(out.data() + at + 1, static_cast<std::uint32_t>(bytes.size()));
  if (!bytes.empty()) std::memcpy(out.data() + at + 5, bytes.data(), bytes.size());
}

Expected<ParsedCheckpoint> ParseCheckpoint(std::span<const std::uint8_t> file, std::uint16_t robot) {
  const auto bad = [](const char* why) { return Error{Errc::kInvalidArgument, why}; };
  if (file.size() < kCheckpointHeadBytes + 4 + 4) return bad("snapshot file: shorter than its head");
  if (std::memcmp(file.data(), kMagic, kMagicBytes) != 0) return bad("snapshot file: bad magic");
  const std::span<const std::uint8_t> body = file.first(file.size() - 4);
  if (Crc32(body) != ReadU32Le(file.data() + body.size()))
    return bad("snapshot file: CRC mismatch (torn or corrupt)");
  Get g(body);
  g.Take(kMagicBytes);
  ParsedCheckpoint out;
  CheckpointMeta& m = out.meta;
  m.robot = g.U16();
  if (m.robot != robot)
    return Error{Errc::kInvalidConfig, "snapshot file: it belongs to another robot id"};
  m.generation = g.U64();
  m.mapper_settings_crc = g.U32();
  m.last_scan_end_s = g.F64();
  m.last_odometry_s = g.F64();
  double pose[7];
  for (double& v : pose) v = g.F64();
  for (double v : pose)
    if (!std::isfinite(v)) return bad("snapshot file: the odometry pose is not finite");
  if (!std::isfinite(m.last_scan_end_s) || !std::isfinite(m.last_odometry_s))
    return bad("snapshot file: a stamp is not finite");
  const Eigen::Quaterniond q(pose[6], pose[3], pose[4], pose[5]);
  if (q.norm() < 0.5) return bad("snapshot file: the odometry rotation is not a rotation");
  m.T_odom_last = Eigen::Isometry3d::Identity();
  m.T_odom_last.linear() = q.normalized().toRotationMatrix();
  m.T_odom_last.translation() << pose[0], pose[1], pose[2];
  m.journal_messages = g.U64();
  const std::uint64_t mapper_bytes = g.U64();
  if (!g.Has(mapper_bytes) || !g.Has(static_cast<std::size_t>(mapper_bytes) + 4))
    return bad("snapshot file: the mapper's length runs past its end");
  out.mapper = g.Take(static_cast<std::size_t>(mapper_bytes));
  out.session_messages = g.U32();
  const std::size_t session_at = g.at();
  for (std::uint32_t i = 0; i < out.session_messages; ++i) {
    if (!g.Has(5)) return bad("snapshot file: a session message runs past its end");
    const std::uint8_t type = g.U8();
    const std::uint32_t length = g.U32();
    if (type >= core::kCollabMessageTypes) return bad("snapshot file: unknown message type");
    if (!g.Has(length)) return bad("snapshot file: a session message runs past its end");
    g.Take(length);
  }
  if (g.at() != body.size()) return bad("snapshot file: bytes after its last message");
  out.session = body.subspan(session_at);
  return out;
}

bool CheckpointGeneration(const std::string& name, bool& is_snapshot, std::uint64_t& generation) {
  if (name == "journal.bin") {
    is_snapshot = false;
    generation = 0;
    return true;
  }
  std::string digits;
  if (name.rfind("journal.", 0) == 0) {
    is_snapshot = false;
    digits = name.substr(8);
  } else if (name.rfind("snapshot.", 0) == 0) {
    is_snapshot = true;
    digits = name.substr(9);
  } else {
    return false;
  }
  if (digits.size() < 5 || digits.compare(digits.size() - 4, 4, ".bin") != 0) return false;
  digits.resize(digits.size() - 4);
  if (digits.empty() || digits.size() > 18 || digits[0] == '0') return false;
  std::uint64_t n = 0;
  for (char c : digits) {
    if (c < '0' || c > '9') return false;
    n = n * 10 + static_cast<std::uint64_t>(c - '0');
  }
  generation = n;
  return true;
}

}  // namespace msgraphs::runtime
