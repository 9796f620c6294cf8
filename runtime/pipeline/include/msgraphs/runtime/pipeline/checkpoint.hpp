// SPDX-License-Identifier: MIT
// The node's checkpoint in generations: a journal of inputs, compacted by snapshots, from which
// a restarted node is mapping again in seconds (docs/runtime.md "Checkpoint and restart").
//
// Why generations: the journal alone (journal.hpp) grows by about 230 kB a keyframe, and a
// restart replays every keyframe (about 50 ms each: over a minute after an hour). Every
// snapshot_every_keyframes keyframes a generation begins: the mapper's snapshot and the session's
// peer state are written to snapshot.N.bin, the journal goes on in journal.N.bin, and what lies
// below the previous durable snapshot is removed. A restart loads the newest snapshot that
// checks and replays the journals from its generation on.
//
// Folder: journal.bin (generation 0, the journal-only layout), snapshot.N.bin + journal.N.bin.
//
// Who does what, so that neither the SLAM thread nor the collab thread waits on a disk:
// - SLAM thread (AfterKeyframe, after the keyframe's records): asks the mapper for a snapshot;
//   the mapper takes it at the end of a keyframe with no full solve pending
//   (LocalMapper::RequestSnapshot). Right after that keyframe's records the journal switches to
//   journal.N.bin, whose first record says where the old one ended (kContinues; no sync on this
//   thread). Its periodic Sync syncs the old journal first if the writer has not yet.
// - Collab thread (CaptureSession, with the session locked): the session's peer state
//   (CollabSession::ExportReceived), and how many peer messages journal.N.bin already holds,
//   which replay skips. Messages are journaled under the session lock, so the count is exact.
// - Writer thread (RunWriter): syncs the old journal, the new one up to the capture (the messages
//   the snapshot counts are on disk before it is) and the folder, writes snapshot.N.tmp, fsyncs,
//   renames it to snapshot.N.bin, syncs the folder, and only then removes the files of
//   generations below the previous durable snapshot (snapshots first, then journals, oldest
//   first), so that a power cut at any step leaves a snapshot and the journals after it.
//
// Restart (Open): snapshots newest first; one that does not check (CRC, robot, generation, the
// mapper settings' CRC, the mapper's own checks) is renamed *.dropped and the next older one is
// tried. The journals from the snapshot's generation on are replayed in order; a journal that
// ends early (torn, corrupt), or one whose successor does not continue it where it ended
// (kContinues), ends the chain there, and later ones are set aside, so the state is always a
// prefix of what happened. Files set aside are renamed before anything is appended, and the
// folder synced; a rename that fails fails Open. With no usable snapshot, journal.bin is replayed from the
// start; when it was already removed, the node starts empty and says so.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "msgraphs/base/expected.hpp"
#include "msgraphs/core/collab/collab_session.hpp"
#include "msgraphs/core/slam/local_mapper.hpp"
#include "msgraphs/runtime/pipeline/checkpoint_file.hpp"
#include "msgraphs/runtime/pipeline/journal.hpp"

namespace msgraphs::runtime {

struct CheckpointSettings {
  std::string dir;
  std::uint16_t robot = 0;
  /// What shapes the map beyond the graph's own config (NodeConfig::mapper_settings_crc): a
  /// snapshot made under other settings is not loaded.
  std::uint32_t mapper_settings_crc = 0;
  /// A generation every this many keyframes; 0: the journal only (journal.bin, never compacted).
  std::size_t snapshot_every_keyframes = 50;
};

/// What Open rebuilt.
struct CheckpointRestore {
  bool from_snapshot = false;
  std::uint64_t snapshot_generation = 0;
  std::size_t session_messages = 0;  ///< peer messages the snapshot gave the session
  /// Peer messages of the snapshot's journal that replay skipped (the snapshot held them).
  std::uint64_t messages_skipped = 0;
  std::size_t journals = 0;          ///< journals replayed
  /// Summed over the journals replayed; the stamps are the newest from the snapshot and them.
  JournalReplay replayed;
  double last_scan_end_s = -1, last_odometry_s = -1;
  Eigen::Isometry3d T_odom_last = Eigen::Isometry3d::Identity();
  double load_s = 0, replay_s = 0;
  std::vector<std::string> set_aside;  ///< files renamed *.dropped, each with why
  bool anything() const { return from_snapshot || replayed.records > 0; }
};

struct CheckpointStats {
  std::uint64_t generation = 0;  ///< the journal being written
  std::uint64_t durable_generation = 0;  ///< the newest snapshot on disk (0: none)
  std::uint64_t snapshots_written = 0, snapshot_failures = 0, files_removed = 0;
  std::uint64_t journal_errors = 0;
  std::uint64_t last_snapshot_bytes = 0;
  double last_write_s = 0;
  std::string last_failure;
};

class Checkpoint {
 public:
  /// Rebuilds `mapper` and `session` (both Init'ed) from `settings.dir` (created when missing)
  /// and opens its newest journal for appending. kInvalidConfig for a folder of another robot;
  /// kIo when the folder cannot be used. Allocates the snapshot buffer (the mapper's
  /// SnapshotBytes) when generations are on.
  static Expected<std::unique_ptr<Checkpoint>> Open(const CheckpointSettings& settings,
                                                    core::LocalMapper& mapper,
                                                    core::CollabSession& session,
                                                    CheckpointRestore& restored);
  ~Checkpoint();
  Checkpoint(const Checkpoint&) = delete;
  Checkpoint& operator=(const Checkpoint&) = delete;

  /// `write(JournalWriter&)` under the journal's lock (any thread); a false result is counted.
  template <class Fn>
  void Journal(Fn&& write) {
    std::lock_guard<std::mutex> lock(journal_mutex_);
    if (!write(*journal_)) journal_errors_.fetch_add(1, std::memory_order_relaxed);
  }

  /// fdatasync of the journal (the SLAM thread's period, and at the mission's end). The journal a
  /// switch closed is synced first: a generation's records are never on disk while the tail of
  /// the one before may not be. While the writer thread is syncing that one, this waits for the
  /// next call. A failure is counted (journal_errors).
  /// `final` (the mission's end): waits for the writer to finish syncing the old journal rather
  /// than leaving the new one for the next call.
  void Sync(bool final = false);
  /// SLAM thread, after each keyframe's records: asks for a snapshot when one is due, and
  /// switches the journal once the mapper took it. `scan_end_s` is that keyframe's scan end.
  /// True when this keyframe's end took a snapshot (its latency holds the mapper's Save), even
  /// if the journal's switch then failed; false when the mapper refused it.
  bool AfterKeyframe(core::LocalMapper& mapper, double scan_end_s);
  /// Whether CaptureSession has work (cheap: the collab thread asks before locking).
  bool session_wanted() const { return state_.load(std::memory_order_acquire) == State::kSession; }
  /// Collab thread, with the session locked: adds the session's peer state to the snapshot.
  /// Allocates (the session part grows to the peers' state).
  void CaptureSession(core::CollabSession& session);
  /// The writer thread: writes each snapshot handed over until `stop` says so (a write begun
  /// is finished first).
  void RunWriter(const std::function<bool()>& stop);
  /// Wakes RunWriter to look at `stop`.
  void Wake();

  CheckpointStats stats() const;

 private:
  enum class State : std::uint8_t { kIdle, kSession, kWrite };
  Checkpoint() = default;
  Status WriteSnapshot();
  void RemoveBelow(std::uint64_t generation);
  std::string PathOf(bool snapshot, std::uint64_t generation) const;

  CheckpointSettings settings_;
  std::mutex journal_mutex_;
  std::optional<JournalWriter> journal_;
  std::atomic<std::uint64_t> journal_errors_{0};
  std::uint64_t generation_ = 0;  // journal_'s (SLAM thread, under journal_mutex_)
  std::size_t keyframes_since_ = 0;
  bool requested_ = false;
  // The snapshot under way: head + the mapper's bytes in file_, the session's messages in
  // session_, the journal it closed, its meta. Handed from thread to thread through state_.
  std::atomic<State> state_{State::kIdle};
  // file_: the head and the mapper's SnapshotBytes, allocated once and never cleared (only the
  // part a snapshot writes is touched: no pages of the bound that a map never reaches).
  std::unique_ptr<std::uint8_t[]> file_;
  std::size_t file_bytes_ = 0;
  std::vector<std::uint8_t> session_;  // the session's part: count, messages, then the CRC
  std::uint32_t session_count_ = 0;
  std::size_t mapper_bytes_ = 0;
  CheckpointMeta meta_;
  // The journal a switch closed, as a descriptor to fdatasync (whoever comes first: the writer
  // thread, or Sync), and whether it is synced; the new journal's, taken at the capture, that the
  // writer syncs before the snapshot that counts its messages becomes durable.
  std::atomic<int> old_fd_{-1};
  std::atomic<bool> old_synced_{true};
  bool folder_synced_ = true;  // the newest journal's name (SLAM thread)
  int new_fd_ = -1;
  std::uint64_t durable_ = 0;  // the newest durable snapshot (0: none)
  std::mutex wake_mutex_;
  std::condition_variable wake_;
  mutable std::mutex stats_mutex_;
  CheckpointStats stats_;
};

}  // namespace msgraphs::runtime
