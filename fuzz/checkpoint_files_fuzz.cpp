// SPDX-License-Identifier: MIT
// libFuzzer target: arbitrary bytes as the checkpoint's files, which a restarted node reads from
// a disk that may have been cut off mid-write or corrupted (checkpoint.hpp). The first byte picks:
//   0: a snapshot file: the magic, then the fuzzer's bytes, then the right CRC-32 (so that the
//      parser past the checksum runs);
//   1: a journal whose records the fuzzer shapes: each is a type byte, a length u16 (the payload
//      is that many of the next bytes) and gets the right CRC, so that every record decoder runs;
//   2: a journal: the header, then the fuzzer's bytes raw (framing, torn tails, bad CRCs).
// Invariants: no crash; a parsed snapshot's parts lie within the file and its messages add up to
// its session part; every record replayed carries finite numbers, and replay's valid bytes never
// pass the file's end.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include "msgraphs/base/byte_order.hpp"
#include "msgraphs/base/crc32.hpp"
#include "msgraphs/runtime/pipeline/checkpoint_file.hpp"
#include "msgraphs/runtime/pipeline/journal.hpp"
#include "sealed_message.hpp"

using namespace msgraphs;
using namespace msgraphs::runtime;

namespace {

void Check(bool ok) {
  if (!ok) std::abort();
}

bool Finite(const Eigen::Isometry3d& T) { return T.matrix().allFinite(); }

struct CheckingSink final : JournalSink {
  void OnOdometry(double t, const Eigen::Isometry3d& T) override { Check(std::isfinite(t) && Finite(T)); }
  void OnScan(std::span<const Eigen::Vector3f> points, std::span<const float> times, double start,
              double end) override {
    Check(points.size() == times.size() && std::isfinite(start) && std::isfinite(end) && start <= end);
    for (const Eigen::Vector3f& p : points) Check(p.allFinite() && p.cwiseAbs().maxCoeff() <= 32.768f);
    for (float t : times) Check(t >= 0 && t <= 0.27f);
  }
  void OnPriors(std::span<const core::PlanePrior> priors) override {
    for (const core::PlanePrior& p : priors) Check(p.normal.allFinite() && std::isfinite(p.d) && p.covariance.allFinite());
  }
  void OnFinish() override {}
  void OnMessage(core::CollabMessageType type, std::span<const std::uint8_t>) override {
    Check(static_cast<int>(type) < core::kCollabMessageTypes);
  }
  void OnMotion(double end, const Eigen::Isometry3d& T, bool) override { Check(std::isfinite(end) && Finite(T)); }
};

void Replay(const std::string& file) {
  std::istringstream in(file);
  CheckingSink sink;
  auto r = ReplayJournal(in, 1, sink);
  if (r) Check(r->valid_bytes <= file.size());
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const std::span<const std::uint8_t> rest(data + 1, size - 1);
  const std::string header = "MSGRAPHS-JOURNAL v1 robot 1\n";
  switch (data[0] % 3) {
    case 0: {
      std::vector<std::uint8_t> body(21);
      std::memcpy(body.data(), "MSGRAPHS-SNAPSHOT v1\n", 21);
      body.insert(body.end(), rest.begin(), rest.end());
      const std::vector<std::uint8_t> file = SealedMessage(body);
      auto parsed = ParseCheckpoint(file, 1);
      if (!parsed) break;
      Check(parsed->mapper.data() >= file.data() &&
            parsed->mapper.data() + parsed->mapper.size() <= file.data() + file.size());
      Check(parsed->meta.T_odom_last.matrix().allFinite());
      std::size_t bytes = 0, count = 0;
      ForEachSessionMessage(*parsed, [&](core::CollabMessageType type, std::span<const std::uint8_t> m) {
        Check(static_cast<int>(type) < core::kCollabMessageTypes);
        bytes += 5 + m.size();
        ++count;
      });
      Check(count == parsed->session_messages && bytes == parsed->session.size());
      break;
    }
    case 1: {
      std::string file = header;
      std::size_t at = 0;
      while (at + 3 <= rest.size()) {
        const std::uint8_t type = rest[at] % 8;
        const std::size_t length =
            std::min<std::size_t>(ReadU16Le(&rest[at + 1]), rest.size() - at - 3);
        const std::span<const std::uint8_t> payload = rest.subspan(at + 3, length);
        at += 3 + length;
        std::vector<std::uint8_t> covered(1, type);
        covered.insert(covered.end(), payload.begin(), payload.end());
        std::uint8_t head[12] = {type, 0, 0, 0};
        WriteU32Le(head + 4, static_cast<std::uint32_t>(length));
        WriteU32Le(head + 8, Crc32(covered));
        file.append(reinterpret_cast<const char*>(head), 12);
        file.append(reinterpret_cast<const char*>(payload.data()), payload.size());
      }
      Replay(file);
      break;
    }
    default:
      Replay(header + std::string(reinterpret_cast<const char*>(rest.data()), rest.size()));
  }
  return 0;
}
