// SPDX-License-Identifier: MIT
// Checkpoint's generations while the node runs (checkpoint.hpp): the SLAM thread switches the
// journal at the mapper's snapshot, the collab thread adds the session, the writer thread makes
// it durable and removes what the previous durable snapshot made redundant.
#include <unistd.h>

#include <cerrno>

#include <algorithm>
#include <chrono>
#include <thread>

#include "checkpoint_folder.hpp"
#include "msgraphs/base/byte_order.hpp"
#include "msgraphs/base/crc32.hpp"
#include "msgraphs/runtime/pipeline/checkpoint.hpp"

namespace msgraphs::runtime {

namespace {

// Appends each exported message to the snapshot's session part.
class SessionPart final : public core::CollabOutbox {
 public:
  SessionPart(std::vector<std::uint8_t>& out, std::uint32_t& count) : out_(out), count_(count) {}
  void Send(core::CollabMessageType type, std::uint16_t, std::span<const std::uint8_t> bytes) override {
    AppendSessionMessage(type, bytes, out_);
    ++count_;
  }

 private:
  std::vector<std::uint8_t>& out_;
  std::uint32_t& count_;
};

}  // namespace

bool Checkpoint::AfterKeyframe(core::LocalMapper& mapper, double scan_end_s) {
  if (settings_.snapshot_every_keyframes == 0) return false;
  ++keyframes_since_;
  if (!requested_) {
    // One snapshot at a time: the next is asked for once the writer is done with the last.
    if (keyframes_since_ < settings_.snapshot_every_keyframes ||
        state_.load(std::memory_order_acquire) != State::kIdle)
      return false;
    // Sealed later: the SLAM thread pays for the copy only, the writer thread for the CRCs.
    mapper.RequestSnapshot(std::span(file_.get() + kCheckpointHeadBytes, file_bytes_ - kCheckpointHeadBytes),
                           SnapshotSeal::kLater);
    requested_ = true;
    // The mapper may take it at this very keyframe's end only if asked before it: it is asked
    // now, for the next keyframe with no solve pending.
    return false;
  }
  auto taken = mapper.TakeSnapshot();
  if (!taken) return false;  // a solve was pending at this keyframe's end
  requested_ = false;
  keyframes_since_ = 0;
  if (!*taken) {
    std::lock_guard<std::mutex> lock(stats_mutex_);
    ++stats_.snapshot_failures;
    stats_.last_failure = taken->error().detail;
    return false;  // no snapshot: nothing of Save in this keyframe's latency to report
  }
  // The snapshot holds this keyframe, whose records went to the journal just before this call:
  // the next generation's journal begins after them.
  const std::uint64_t next = generation_ + 1;
  auto writer = JournalWriter::Open(PathOf(false, next), settings_.robot, 0);
  if (!writer) {
    std::lock_guard<std::mutex> lock(stats_mutex_);
    ++stats_.snapshot_failures;
    stats_.last_failure = writer.error().detail;
    return true;
  }
  meta_ = CheckpointMeta{};
  meta_.robot = settings_.robot;
  meta_.generation = next;
  meta_.mapper_settings_crc = settings_.mapper_settings_crc;
  meta_.last_scan_end_s = scan_end_s;
  const core::OdometryBuffer& odometry = mapper.odometry();
  if (odometry.size() > 0) {
    meta_.last_odometry_s = odometry.stamp(odometry.size() - 1);
    meta_.T_odom_last = odometry.pose(odometry.size() - 1);
  }
  mapper_bytes_ = **taken;
  // A journal closed at an earlier switch whose snapshot failed before the writer synced it.
  if (const int earlier = old_fd_.exchange(-1); earlier >= 0) {
    if (::fdatasync(earlier) != 0) journal_errors_.fetch_add(1, std::memory_order_relaxed);
    ::close(earlier);
  }
  {
    std::lock_guard<std::mutex> lock(journal_mutex_);
    // Its first record: where the old journal ends, which a restart checks before continuing.
    if (!writer->Continues(generation_, journal_->bytes())) {
      std::lock_guard<std::mutex> stats_lock(stats_mutex_);
      ++stats_.snapshot_failures;
      stats_.last_failure = "cannot write the new journal's first record";
      return true;
    }
    writer->TakeBuffersFrom(*journal_);
    const int old = journal_->DuplicateDescriptor();
    if (old >= 0) {
      old_synced_.store(false, std::memory_order_release);
      old_fd_.store(old, std::memory_order_release);
    } else if (!journal_->Sync()) {  // no descriptor to hand over (EMFILE): synced here, once
      journal_errors_.fetch_add(1, std::memory_order_relaxed);
    }
    journal_.emplace(std::move(*writer));  // the old writer closes; its dup stays open
    generation_ = next;
    folder_synced_ = false;
  }
  {
    std::lock_guard<std::mutex> lock(stats_mutex_);
    stats_.generation = next;
  }
  state_.store(State::kSession, std::memory_order_release);
  return true;
}

void Checkpoint::CaptureSession(core::CollabSession& session) {
  if (state_.load(std::memory_order_acquire) != State::kSession) return;
  session_.assign(4, 0);  // the count, written when known
  session_count_ = 0;
  SessionPart part(session_, session_count_);
  const core::CollabExportStats exported = session.ExportReceived(part);
  if (exported.failed > 0) {
    // A peer's state missing from the snapshot would be lost once the journals holding it are
    // removed: no snapshot this time (the new journal goes on; the chain stays whole).
    std::lock_guard<std::mutex> lock(stats_mutex_);
    ++stats_.snapshot_failures;
    stats_.last_failure = "a peer's state did not encode";
    state_.store(State::kIdle, std::memory_order_release);
    return;
  }
  {
    // Every peer message journaled since the switch was received by the session before this
    // (both happen under the session's lock): the export holds them; replay skips them.
    std::lock_guard<std::mutex> lock(journal_mutex_);
    meta_.journal_messages = journal_->messages();
    new_fd_ = journal_->DuplicateDescriptor();
  }
  if (new_fd_ < 0) {
    // The new journal could not be synced before the snapshot that counts its messages.
    std::lock_guard<std::mutex> lock(stats_mutex_);
    ++stats_.snapshot_failures;
    stats_.last_failure = "no descriptor to sync the new journal";
    state_.store(State::kIdle, std::memory_order_release);
    return;
  }
  state_.store(State::kWrite, std::memory_order_release);
  Wake();
}

void Checkpoint::Wake() {
  std::lock_guard<std::mutex> lock(wake_mutex_);
  wake_.notify_all();
}

void Checkpoint::RunWriter(const std::function<bool()>& stop) {
  for (;;) {
    {
      std::unique_lock<std::mutex> lock(wake_mutex_);
      wake_.wait_for(lock, std::chrono::milliseconds(200), [&] {
        return stop() || state_.load(std::memory_order_acquire) == State::kWrite;
      });
    }
    if (state_.load(std::memory_order_acquire) == State::kWrite) {
      const auto t0 = std::chrono::steady_clock::now();
      const Status s = WriteSnapshot();
      std::lock_guard<std::mutex> lock(stats_mutex_);
      if (s) {
        ++stats_.snapshots_written;
        stats_.durable_generation = durable_;
        stats_.last_write_s =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      } else {
        ++stats_.snapshot_failures;
        stats_.last_failure = s.error().detail;
      }
      state_.store(State::kIdle, std::memory_order_release);
    }
    if (stop()) return;
  }
}

void Checkpoint::Sync(bool final) {
  bool ok = true;
  if (const int old = old_fd_.exchange(-1); old >= 0) {
    ok = ::fdatasync(old) == 0;
    ::close(old);
    old_synced_.store(true, std::memory_order_release);
  }
  // The writer thread holds the old one and is syncing it: the new one waits for the next call,
  // or, at the mission's end, for the writer.
  for (int waited_ms = 0; final && !old_synced_.load(std::memory_order_acquire) && waited_ms < 10000;
       ++waited_ms)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  // A failed sync of the old one leaves the new one unsynced too (its records must not be on
  // disk without the old one's tail); the next call tries again with the new one only.
  if (ok && old_synced_.load(std::memory_order_acquire)) {
    {
      std::lock_guard<std::mutex> lock(journal_mutex_);
      ok = static_cast<bool>(journal_->Sync());
    }
    // The newest journal's name, once after each switch (the writer syncs it too, but not when
    // that generation's snapshot failed before).
    if (ok && !folder_synced_) ok = folder_synced_ = static_cast<bool>(SyncFolder(settings_.dir));
  }
  if (!ok) journal_errors_.fetch_add(1, std::memory_order_relaxed);
}

Status Checkpoint::WriteSnapshot() {
  // The journal the switch closed: complete on disk before anything relies on the new one.
  if (const int old = old_fd_.exchange(-1); old >= 0) {
    const bool synced = ::fdatasync(old) == 0;
    ::close(old);
    old_synced_.store(true, std::memory_order_release);
    if (!synced) {
      if (new_fd_ >= 0) ::close(new_fd_);
      new_fd_ = -1;
      return Error{Errc::kIo, "cannot fdatasync the journal the switch closed", errno};
    }
  }
  // The new journal up to the capture: the peer messages the snapshot counts as held are on disk
  // before the snapshot is (a restart skips exactly that many).
  if (new_fd_ >= 0) {
    const bool synced = ::fdatasync(new_fd_) == 0;
    ::close(new_fd_);
    new_fd_ = -1;
    if (!synced) return Error{Errc::kIo, "cannot fdatasync the new journal", errno};
  }
  // The new journal's name: a snapshot never exists without its journal's entry.
  if (Status s = SyncFolder(settings_.dir); !s) return s;
  // The mapper's CRCs, left by the SLAM thread (RequestSnapshot).
  if (Status s = core::LocalMapper::SealSnapshot(std::span(file_.get() + kCheckpointHeadBytes, mapper_bytes_)); !s)
    return s;
  // The file: head and mapper's bytes (file_), then the session's count and messages and the
  // CRC-32 of everything before it (session_).
  WriteCheckpointHead(meta_, mapper_bytes_,
                      std::span<std::uint8_t, kCheckpointHeadBytes>(file_.get(), kCheckpointHeadBytes));
  const std::span<const std::uint8_t> head(file_.get(), kCheckpointHeadBytes + mapper_bytes_);
  WriteU32Le(session_.data(), session_count_);
  const std::uint32_t crc = Crc32Continue(Crc32(head), session_);
  session_.resize(session_.size() + 4);
  WriteU32Le(session_.data() + session_.size() - 4, crc);
  const std::span<const std::uint8_t> parts[] = {head, session_};
  const Status written = WriteFileDurably(settings_.dir, PathOf(true, meta_.generation), parts);
  {
    std::lock_guard<std::mutex> lock(stats_mutex_);
    stats_.last_snapshot_bytes = head.size() + session_.size();
  }
  if (!written) return written;
  const std::uint64_t previous = durable_;
  durable_ = meta_.generation;
  // What the previous durable snapshot made redundant: everything below it. The previous one
  // and its journals stay as the fallback should the new one not check at the next start.
  if (previous > 0) RemoveBelow(previous);
  return Ok();
}

void Checkpoint::RemoveBelow(std::uint64_t generation) {
  auto folder = ListCheckpointFolder(settings_.dir);
  if (!folder) return;
  std::uint64_t removed = 0;
  // Snapshots first: a journal is never gone while a snapshot that needs it is there.
  for (std::uint64_t g : folder->snapshots)
    if (g < generation && ::unlink(PathOf(true, g).c_str()) == 0) ++removed;
  static_cast<void>(SyncFolder(settings_.dir));  // the snapshots' removal first on disk too
  for (std::uint64_t g : folder->journals)
    if (g < generation && ::unlink(PathOf(false, g).c_str()) == 0) ++removed;
  static_cast<void>(SyncFolder(settings_.dir));
  std::lock_guard<std::mutex> lock(stats_mutex_);
  stats_.files_removed += removed;
}

}  // namespace msgraphs::runtime
