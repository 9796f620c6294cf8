// SPDX-License-Identifier: MIT
// The node's checkpoint: an append-only journal of everything that changes the robot's state,
// from which a restarted node rebuilds it by replay.
//
// Why a journal of inputs rather than a snapshot of the S-Graph: the local mapper's state is a
// function of its keyframe scans, the odometry, the wall priors it was given and its Finish
// calls, and the session's of the peers' messages. Scans that are not keyframes change only
// the scan tracking, whose result a keyframe carries as its motion (kMotion, written before
// its kScan): replay makes the keyframe from it (LocalMapper::ReplayKeyframe). Replaying those rebuilds every part of it (graph, stored clouds, planes, rooms,
// loop-closure candidates, free-space grid) without a serialiser per class that would have to
// follow each of them. The cost: a restart replays the keyframes (about 50 ms each here).
//
// File: "MSGRAPHS-JOURNAL v1 robot N\n", then records: type u8 | 0 u8 x3 | length u32 |
// CRC-32 u32 of type and payload | payload (little-endian). Each record is written with one
// write() (complete in the kernel when the process dies), and the file is fsync'ed every
// sync period (complete on disk after a power cut up to the last sync). A torn or corrupt
// tail is where replay stops, reported, and the file is truncated there before appending.
//
// Record payloads:
//   kOdometry  stamp f64, x y z f64, qx qy qz qw f64                        (64 bytes)
//   kScan      start f64, end f64, points u32, points x (x y z i16 in mm, time u16 in 4 us)
//              (only points the mapper can use: within max_range_m; 8 bytes a point)
//   kPriors    count u32, count x (plane u32, normal f64 x3, d f64, covariance f64 x9)
//   kFinish    (empty)
//   kMessage   type u8, bytes: a collab message from a peer (room clouds are not kept: they
//              are requested again when needed)
//   kMotion    end f64, x y z f64, qx qy qz qw f64, tracked u8: the next keyframe's motion since
//              the previous one, as tracked live (65 bytes). A journal without them (written
//              before scan tracking) replays its keyframe scans through AddScan.
//   kContinues generation u64, bytes u64: the first record of a checkpoint generation's
//              journal (checkpoint.hpp): the journal it continues, and where that one's records
//              ended when this one began. A restart continues into this journal only when the
//              previous one replayed to exactly there (never over a hole).
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <istream>
#include <span>
#include <string>
#include <vector>

#include "msgraphs/base/expected.hpp"
#include "msgraphs/core/collab/collab_session.hpp"
#include "msgraphs/core/graph/s_graph.hpp"

namespace msgraphs::runtime {

enum class JournalRecord : std::uint8_t {
  kOdometry = 1,
  kScan = 2,
  kPriors = 3,
  kFinish = 4,
  kMessage = 5,
  kMotion = 6,
  kContinues = 7
};

class JournalWriter {
 public:
  /// Opens (creates) `path` for appending after `valid_bytes` (what replay accepted; a torn
  /// tail beyond it is cut). A new file gets the header for `robot`.
  static Expected<JournalWriter> Open(const std::string& path,
                                      std::uint16_t robot,
                                      std::uint64_t valid_bytes);
  JournalWriter(JournalWriter&& other) noexcept;
  JournalWriter& operator=(JournalWriter&&) = delete;
  ~JournalWriter();

  Status Odometry(double stamp_s, const Eigen::Isometry3d& T_odom_base);
  Status Scan(std::span<const Eigen::Vector3f> points,
              std::span<const float> time_offset_s,
              double start_s,
              double end_s,
              float max_range_m);
  Status Priors(std::span<const core::PlanePrior> priors);
  Status Finish();
  Status Message(core::CollabMessageType type, std::span<const std::uint8_t> bytes);
  /// The motion of the keyframe whose scan follows (ending at `end_s`).
  Status Motion(double end_s, const Eigen::Isometry3d& T_last_new, bool tracked);
  /// The first record of a generation's journal: it continues `generation`'s, whose records
  /// ended at `bytes`.
  Status Continues(std::uint64_t generation, std::uint64_t bytes);
  /// fsync: everything written so far survives a power cut.
  Status Sync();
  /// A second descriptor of the file (the caller closes it): to fdatasync it on another thread,
  /// outside the journal's lock, or after this writer is gone. -1 when dup fails.
  int DuplicateDescriptor() const;
  std::uint64_t bytes() const { return bytes_; }
  std::uint64_t records() const { return records_; }
  /// kMessage records written through this writer.
  std::uint64_t messages() const { return messages_; }
  /// Swaps the record buffers with `other` (grown to the largest scan): a journal that
  /// replaces another at a checkpoint generation does not grow its own again.
  void TakeBuffersFrom(JournalWriter& other);

 private:
  explicit JournalWriter(int fd, std::uint64_t bytes) : fd_(fd), bytes_(bytes) {}
  Status Write(JournalRecord type, std::span<const std::uint8_t> payload);
  int fd_ = -1;
  std::uint64_t bytes_ = 0, records_ = 0, messages_ = 0;
  std::vector<std::uint8_t> buffer_, record_;  // grow to the largest scan once, then reused
};

/// What replay found.
struct JournalReplay {
  std::uint64_t valid_bytes = 0;  ///< where the good records end (the writer appends there)
  std::uint64_t records = 0, odometry = 0, scans = 0, priors = 0, finishes = 0, messages = 0,
                motions = 0;
  double last_scan_end_s = -1, last_odometry_s = -1;
  /// Its kContinues record, when it has one: the journal it continues and where that one ended.
  bool continues = false;
  std::uint64_t continues_generation = 0, continues_bytes = 0;
  std::string stopped;  ///< empty when the file ended cleanly, else why replay stopped early
};

/// Receives the records in order.
class JournalSink {
 public:
  virtual ~JournalSink() = default;
  virtual void OnOdometry(double stamp_s, const Eigen::Isometry3d& T_odom_base) = 0;
  virtual void OnScan(std::span<const Eigen::Vector3f> points,
                      std::span<const float> time_offset_s,
                      double start_s,
                      double end_s) = 0;
  virtual void OnPriors(std::span<const core::PlanePrior> priors) = 0;
  virtual void OnFinish() = 0;
  virtual void OnMessage(core::CollabMessageType type, std::span<const std::uint8_t> bytes) = 0;
  virtual void OnMotion(double end_s, const Eigen::Isometry3d& T_last_new, bool tracked) = 0;
};

/// Replays `path` into `sink`. A missing file is an empty journal; a header for another robot
/// is an error (kInvalidConfig): the checkpoint folder belongs to one robot.
Expected<JournalReplay> ReplayJournal(const std::string& path,
                                      std::uint16_t robot,
                                      JournalSink& sink);
/// The kContinues record at the start of `path` (header and first record only, CRC-checked):
/// false in `found` when the file is missing, empty or starts otherwise.
Status ReadContinuation(const std::string& path, std::uint16_t robot, bool& found,
                        std::uint64_t& generation, std::uint64_t& bytes);
/// The same from a stream (the fuzz target's bytes). A record whose numbers are not finite is
/// where replay stops, as at a bad CRC.
Expected<JournalReplay> ReplayJournal(std::istream& in, std::uint16_t robot, JournalSink& sink);

}  // namespace msgraphs::runtime
