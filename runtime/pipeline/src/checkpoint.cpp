// SPDX-License-Identifier: MIT
// Checkpoint::Open: the restart (checkpoint.hpp). The folder's generations are found, the newest
// snapshot that checks is loaded, and the journals from its generation on are replayed.
#include "msgraphs/runtime/pipeline/checkpoint.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <filesystem>
#include <map>

#include "checkpoint_folder.hpp"

namespace msgraphs::runtime {

namespace {

// Discards what the session would send while it is rebuilt.
class NullOutbox final : public core::CollabOutbox {
 public:
  void Send(core::CollabMessageType, std::uint16_t, std::span<const std::uint8_t>) override {}
};

// Rebuilds the mapper and the session from a journal.
class Restore final : public JournalSink {
 public:
  Restore(core::LocalMapper& mapper, core::CollabSession& session)
      : mapper_(mapper), session_(session) {}
  void OnOdometry(double stamp_s, const Eigen::Isometry3d& T) override {
    static_cast<void>(mapper_.AddOdometry(stamp_s, T));
    last_odometry = T;
  }
  void OnScan(std::span<const Eigen::Vector3f> points,
              std::span<const float> times,
              double start_s,
              double end_s) override {
    // A keyframe made as it was live (its tracked motion), or, from a journal written before
    // scan tracking, through AddScan.
    if (have_motion_ && motion_end_s_ == end_s) {
      static_cast<void>(mapper_.ReplayKeyframe({points, times, start_s, end_s}, motion_));
    } else {
      static_cast<void>(mapper_.AddScan({points, times, start_s, end_s}));
    }
    have_motion_ = false;
  }
  void OnMotion(double end_s, const Eigen::Isometry3d& T_last_new, bool tracked) override {
    motion_.T_last_new = T_last_new;
    motion_.tracked = tracked;
    motion_end_s_ = end_s;
    have_motion_ = true;
  }
  void OnPriors(std::span<const core::PlanePrior> priors) override {
    static_cast<void>(mapper_.SetPlanePriors(priors));
  }
  void OnFinish() override { static_cast<void>(mapper_.Finish()); }
  void OnMessage(core::CollabMessageType type, std::span<const std::uint8_t> bytes) override {
    // The snapshot's session part holds the first messages of its generation's journal.
    if (skip_messages > 0) {
      --skip_messages;
      return;
    }
    static_cast<void>(session_.Receive(type, bytes, outbox_));
  }
  Eigen::Isometry3d last_odometry = Eigen::Isometry3d::Identity();  ///< odometry frame, newest
  std::uint64_t skip_messages = 0;

 private:
  core::LocalMapper& mapper_;
  core::CollabSession& session_;
  NullOutbox outbox_;
  core::LocalMapper::KeyframeMotion motion_;
  double motion_end_s_ = 0;
  bool have_motion_ = false;
};

double SecondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void Add(JournalReplay& sum, const JournalReplay& r) {
  sum.records += r.records;
  sum.odometry += r.odometry;
  sum.scans += r.scans;
  sum.priors += r.priors;
  sum.finishes += r.finishes;
  sum.messages += r.messages;
  sum.motions += r.motions;
  if (r.last_scan_end_s >= 0) sum.last_scan_end_s = r.last_scan_end_s;
  if (r.last_odometry_s >= 0) sum.last_odometry_s = r.last_odometry_s;
  if (!r.stopped.empty()) sum.stopped = r.stopped;
}

}  // namespace

Checkpoint::~Checkpoint() {
  // Descriptors handed between threads and not yet synced (the process is ending: the kernel has
  // the bytes; a power cut now loses at most what the sync period allows).
  if (const int old = old_fd_.exchange(-1); old >= 0) ::close(old);
  if (new_fd_ >= 0) ::close(new_fd_);
}

std::string Checkpoint::PathOf(bool snapshot, std::uint64_t generation) const {
  return CheckpointPath(settings_.dir, snapshot, generation);
}

Expected<std::unique_ptr<Checkpoint>> Checkpoint::Open(const CheckpointSettings& settings,
                                                       core::LocalMapper& mapper,
                                                       core::CollabSession& session,
                                                       CheckpointRestore& restored) {
  restored = CheckpointRestore{};
  std::unique_ptr<Checkpoint> c(new Checkpoint());
  c->settings_ = settings;
  std::error_code ec;
  std::filesystem::create_directories(settings.dir, ec);
  auto folder = ListCheckpointFolder(settings.dir);
  if (!folder) return folder.error();
  bool rename_failed = false;
  const auto set_aside = [&](const std::string& path, const std::string& why) {
    const std::string to = SetAside(path);
    rename_failed = rename_failed || to.empty();
    restored.set_aside.push_back(path + " -> " + (to.empty() ? "(rename FAILED)" : to) + ": " + why);
  };
  // Entries under our names that are not regular files (a FIFO would block the reader, a link
  // redirect it) are never read.
  for (const std::string& path : folder->not_regular) set_aside(path, "not a regular file");

  // The newest snapshot that checks.
  const auto t0 = std::chrono::steady_clock::now();
  std::optional<CheckpointMeta> base;
  std::vector<std::uint8_t> bytes;
  for (auto it = folder->snapshots.rbegin(); it != folder->snapshots.rend() && !base; ++it) {
    const std::uint64_t g = *it;
    const std::string path = c->PathOf(true, g);
    const std::size_t cap = kCheckpointHeadBytes + mapper.SnapshotBytes() + (256u << 20);
    if (Status s = ReadWholeFile(path, cap, bytes); !s) {
      set_aside(path, s.error().detail);
      continue;
    }
    auto parsed = ParseCheckpoint(bytes, settings.robot);
    if (!parsed) {
      if (parsed.error().code == Errc::kInvalidConfig) return parsed.error();
      set_aside(path, parsed.error().detail);
      continue;
    }
    if (parsed->meta.generation != g) {
      set_aside(path, "its generation is not its name's");
      continue;
    }
    if (parsed->meta.mapper_settings_crc != settings.mapper_settings_crc) {
      set_aside(path, "made under other mapper settings");
      continue;
    }
    if (Status s = mapper.Load(parsed->mapper); !s) {
      set_aside(path, s.error().detail);
      continue;
    }
    NullOutbox discard;
    ForEachSessionMessage(*parsed, [&](core::CollabMessageType type, std::span<const std::uint8_t> m) {
      static_cast<void>(session.Receive(type, m, discard));
      ++restored.session_messages;
    });
    base = parsed->meta;
  }
  bytes = {};
  restored.load_s = SecondsSince(t0);

  Restore sink(mapper, session);
  std::uint64_t first = 0;
  if (base) {
    restored.from_snapshot = true;
    restored.snapshot_generation = base->generation;
    restored.last_scan_end_s = base->last_scan_end_s;
    restored.last_odometry_s = base->last_odometry_s;
    sink.last_odometry = base->T_odom_last;
    sink.skip_messages = base->journal_messages;
    c->durable_ = first = base->generation;
  } else if (!folder->journals.empty() && folder->journals.front() != 0) {
    // No snapshot to continue, and journal.bin, where the journals begin, was removed after two
    // snapshots that are gone now: nothing to rebuild from. Start empty, the evidence kept aside.
    for (std::uint64_t j : folder->journals)
      set_aside(c->PathOf(false, j), "no snapshot to continue and no journal.bin to begin");
    folder->journals.clear();
  }

  // The journals from `first` on, each continuing the last: one that ended early or a gap ends
  // the chain, and what follows is set aside (never replayed over a hole).
  const auto t1 = std::chrono::steady_clock::now();
  c->generation_ = first;
  std::uint64_t append_at = 0;
  bool chain_ended = false, short_journal = base.has_value() && base->journal_messages > 0;
  for (std::uint64_t j : folder->journals) {
    if (j < first) continue;
    const std::string path = c->PathOf(false, j);
    if (!chain_ended && restored.journals > 0 && j == c->generation_ + 1) {
      // It must say it continues the last one where that one's records end.
      bool found = false;
      std::uint64_t from = 0, at = 0;
      if (Status s = ReadContinuation(path, settings.robot, found, from, at); !s) return s.error();
      if (!found || from != c->generation_ || at != append_at) {
        chain_ended = true;
        set_aside(path, "it does not continue the journal before where that one ends");
        continue;
      }
    }
    if (chain_ended || j != c->generation_ + (restored.journals == 0 ? 0 : 1)) {
      chain_ended = true;
      set_aside(path, "after a journal that ended early or is missing");
      continue;
    }
    auto r = ReplayJournal(path, settings.robot, sink);
    if (!r) return r.error();
    if (j == first && base) {
      // Only the snapshot's own generation's journal had them. Fewer there than counted: the
      // disk lost some (see below).
      restored.messages_skipped = base->journal_messages - sink.skip_messages;
      short_journal = sink.skip_messages > 0;
      sink.skip_messages = 0;
    }
    Add(restored.replayed, *r);
    ++restored.journals;
    c->generation_ = j;
    append_at = r->valid_bytes;
    chain_ended = !r->stopped.empty();
  }
  restored.replay_s = SecondsSince(t1);
  if (restored.replayed.last_scan_end_s >= 0) restored.last_scan_end_s = restored.replayed.last_scan_end_s;
  if (restored.replayed.last_odometry_s >= 0) restored.last_odometry_s = restored.replayed.last_odometry_s;
  restored.T_odom_last = sink.last_odometry;
  // Snapshots older than the one loaded stay until the next is durable (RemoveBelow).
  if (rename_failed) return Error{Errc::kIo, "checkpoint: a file to set aside could not be renamed"};
  if (!restored.set_aside.empty()) {
    // The renames on disk before anything is appended: else a power cut could bring a file
    // set aside back behind the new records.
    if (Status s = SyncFolder(settings.dir); !s) return s.error();
  }
  if (short_journal && c->generation_ == first) {
    // The snapshot's journal holds fewer peer messages than it counted (a disk that lost them):
    // the session has them from the snapshot, but messages appended to that journal now would be
    // skipped at the next restart. The node goes on in a new generation's journal instead.
    restored.set_aside.push_back(c->PathOf(false, c->generation_) +
                                 ": holds fewer peer messages than its snapshot counted; "
                                 "a new journal begins");
    std::uint64_t ends_at = 0;
    {
      // The short journal (created when missing, cut after its last good record), synced: the
      // next one continues it from its end.
      auto cut = JournalWriter::Open(c->PathOf(false, c->generation_), settings.robot, append_at);
      if (!cut) return cut.error();
      if (Status s = cut->Sync(); !s) return s.error();
      ends_at = cut->bytes();
    }
    auto next = JournalWriter::Open(c->PathOf(false, c->generation_ + 1), settings.robot, 0);
    if (!next) return next.error();
    if (Status s = next->Continues(c->generation_, ends_at); !s) return s.error();
    if (Status s = next->Sync(); !s) return s.error();
    if (Status s = SyncFolder(settings.dir); !s) return s.error();
    c->journal_.emplace(std::move(*next));
    c->generation_ += 1;
  }
  // The journals before the newest on disk before anything is appended to it: a crash (no power
  // cut) may have left their tails in the page cache only, and the newest's records must never
  // be durable while theirs may not be.
  for (std::uint64_t j : folder->journals) {
    if (j < first || j >= c->generation_) continue;
    if (Status s = SyncFile(c->PathOf(false, j)); !s) return s.error();
  }

  // Append to the newest journal of the chain (where its good records end).
  if (!c->journal_) {
    auto writer = JournalWriter::Open(c->PathOf(false, c->generation_), settings.robot, append_at);
    if (!writer) return writer.error();
    c->journal_.emplace(std::move(*writer));
  }
  if (settings.snapshot_every_keyframes > 0) {
    c->file_bytes_ = kCheckpointHeadBytes + mapper.SnapshotBytes();
    c->file_.reset(new std::uint8_t[c->file_bytes_]);  // not zeroed: see file_
  }
  c->stats_.generation = c->generation_;
  c->stats_.durable_generation = c->durable_;
  return c;
}

CheckpointStats Checkpoint::stats() const {
  std::lock_guard<std::mutex> lock(stats_mutex_);
  CheckpointStats s = stats_;
  s.journal_errors = journal_errors_.load(std::memory_order_relaxed);
  return s;
}

}  // namespace msgraphs::runtime
