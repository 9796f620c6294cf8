// SPDX-License-Identifier: MIT
// The checkpoint in generations (checkpoint.hpp) with the real mapper, session, files and writer
// thread: a robot walks, its journal switches at each snapshot, the writer makes them durable and
// removes what they made redundant; killed, it restarts from the newest snapshot and the journal
// since, and maps the rest of the walk as the robot that was never killed. A snapshot that does
// not check falls back to the one before; another robot's folder is refused; a snapshot made
// under other mapper settings is not loaded.
#include "msgraphs/runtime/pipeline/checkpoint.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <thread>

#include "alloc_counter.hpp"
#include "box_room_walk.hpp"
#include "msgraphs/core/collab/distilled_codec.hpp"

namespace msgraphs::runtime {
namespace {

namespace fs = std::filesystem;
using core::LocalMapper;
using core::LocalMapperConfig;

constexpr std::size_t kSteps = 40, kKillAt = 31, kEvery = 6;

LocalMapperConfig WalkConfig() {
  LocalMapperConfig config = core::SmallConfig(64, 256);
  config.cloud_store_points = 150000;
  config.full_solve_lag_keyframes = 3;
  config.graph.local_max_seconds = 1e9;  // the iteration caps only: never the machine's load
  config.graph.full_max_seconds = 1e9;
  return config;
}

core::CollabSessionConfig SessionConfig() {
  core::CollabSessionConfig config;
  config.robot = 1;
  config.max_peers = 2;
  return config;
}

// Robot 2's graph at `version`, as a delta since the version before: each version adds one
// wall (its own version), so a message lost on the way (or skipped at replay) leaves a wall
// missing for good, and one applied twice changes nothing.
std::vector<std::uint8_t> PeerGraph(std::uint32_t version) {
  core::DistilledGraph g;
  g.Init(256, 4);
  g.robot = 2;
  g.version = version;
  for (std::uint32_t i = 0; i < version && i < 256; ++i) {
    core::DistilledWall w;
    w.id = i;
    w.version = i + 1;
    const double a = 0.1 * i;
    w.normal = Eigen::Vector3d(std::cos(a), std::sin(a), 0);
    w.d = -2.0 - 0.01 * i;
    w.covariance = Eigen::Vector3d(1e-4, 2e-4, 4e-4).asDiagonal();
    w.a = {0, 0};
    w.b = {1, 0};
    g.walls.push_back(w);
  }
  const std::uint32_t since = version - 1;
  std::vector<std::uint8_t> bytes(core::DistilledEncodedSize(g, since));
  EXPECT_TRUE(core::EncodeDistilled(g, since, bytes));
  return bytes;
}

struct NullOutbox final : core::CollabOutbox {
  void Send(core::CollabMessageType, std::uint16_t, std::span<const std::uint8_t>) override {}
};

struct RecordingOutbox final : core::CollabOutbox {
  std::vector<std::vector<std::uint8_t>> sent;
  void Send(core::CollabMessageType, std::uint16_t, std::span<const std::uint8_t> b) override {
    sent.emplace_back(b.begin(), b.end());
  }
};

// One robot as the node runs it: the mapper and the session fed in order, each input journaled
// after it went in, the writer thread beside.
class Robot {
 public:
  Robot(const std::string& dir, std::size_t every, std::uint32_t settings_crc = 7,
        std::uint16_t robot = 1) {
    config_ = WalkConfig();
    EXPECT_TRUE(mapper.Init(config_));
    EXPECT_TRUE(session.Init(SessionConfig(), config_.graph, -0.5));
    CheckpointSettings settings;
    settings.dir = dir;
    settings.robot = robot;
    settings.mapper_settings_crc = settings_crc;
    settings.snapshot_every_keyframes = every;
    auto c = Checkpoint::Open(settings, mapper, session, restored);
    if (!c) {
      open_error = c.error();
      return;
    }
    checkpoint = std::move(*c);
    writer_ = std::jthread([this] { checkpoint->RunWriter([this] { return stop_.load(); }); });
  }
  ~Robot() { Kill(); }

  // Step i of the walk; a peer's graph version arrives at some steps, one just between a
  // journal switch and the session's capture (it must be in the snapshot and skipped at
  // replay), the next after it (it must be replayed).
  void Step(const core::Walk& walk, std::size_t i) {
    const double t = 10.0 + static_cast<double>(i);
    for (double s : {t - 0.15, t + 0.05}) {
      EXPECT_TRUE(mapper.AddOdometry(s, walk.odometry[i]));
      checkpoint->Journal([&](JournalWriter& j) { return static_cast<bool>(j.Odometry(s, walk.odometry[i])); });
    }
    const auto points = core::ScanAt(walk.truth[i], config_, static_cast<std::uint32_t>(i + 1));
    const std::vector<float> times(points.size(), 0.1f);
    auto outcome = mapper.AddScan({points, times, t - 0.1, t});
    ASSERT_TRUE(outcome);
    if (*outcome == core::ScanOutcome::kKeyframe) {
      const LocalMapper::KeyframeMotion& motion = mapper.last_keyframe_motion();
      checkpoint->Journal([&](JournalWriter& j) {
        return j.Motion(t, motion.T_last_new, motion.tracked) &&
               j.Scan(points, times, t - 0.1, t, config_.max_range_m);
      });
      checkpoint->AfterKeyframe(mapper, t);
    }
    if (i % 4 == 1 || checkpoint->session_wanted()) Peer();
    checkpoint->Sync();  // the node's sync period, here every scan
    if (checkpoint->session_wanted()) {
      checkpoint->CaptureSession(session);
      ++captures;
      // A disk that keeps up: the snapshot is durable before the walk goes on.
      for (int w = 0; w < 20000 && !Idle(); ++w)
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
      EXPECT_TRUE(Idle());
      Peer();
    }
  }

  void Peer() {
    const std::vector<std::uint8_t> bytes = PeerGraph(++peer_version_);
    NullOutbox out;
    if (session.Receive(core::CollabMessageType::kDistilledGraph, bytes, out))
      checkpoint->Journal([&](JournalWriter& j) {
        return static_cast<bool>(j.Message(core::CollabMessageType::kDistilledGraph, bytes));
      });
  }

  // Each capture is one write, durable or failed.
  bool Idle() const {
    const CheckpointStats s = checkpoint->stats();
    return s.snapshots_written + s.snapshot_failures >= captures;
  }

  // The process dies: the writer stops, the files stay as they are (no Finish record).
  void Kill() {
    stop_ = true;
    if (checkpoint) checkpoint->Wake();
    if (writer_.joinable()) writer_.join();
    checkpoint.reset();
  }

  std::vector<std::vector<std::uint8_t>> Exported() {
    RecordingOutbox out;
    session.ExportReceived(out);
    return out.sent;
  }

  LocalMapper mapper;
  core::CollabSession session;
  std::unique_ptr<Checkpoint> checkpoint;
  CheckpointRestore restored;
  Error open_error{Errc::kInvalidArgument, ""};
  std::size_t captures = 0;
  std::uint32_t peer_version_ = 0;

 private:
  LocalMapperConfig config_;
  std::atomic<bool> stop_{false};
  std::jthread writer_;
};

std::string FreshDir(const char* name) {
  const fs::path dir = fs::temp_directory_path() /
                       ("msgraphs_checkpoint_" + std::string(name) + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  return dir.string();
}

std::vector<std::string> Files(const std::string& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

// The largest distance between the two mappers' keyframe positions (same slots).
double LargestGap(const LocalMapper& a, const LocalMapper& b) {
  double gap = 0;
  EXPECT_EQ(a.graph().keyframe_slots(), b.graph().keyframe_slots());
  for (std::uint32_t k = 0; k < a.graph().keyframe_slots(); ++k) {
    EXPECT_EQ(a.graph().keyframe_active(k), b.graph().keyframe_active(k)) << k;
    if (!a.graph().keyframe_active(k) || !b.graph().keyframe_active(k)) continue;
    gap = std::max(gap, (a.graph().keyframe_pose(k).translation() -
                         b.graph().keyframe_pose(k).translation()).norm());
  }
  return gap;
}

// A walk of kSteps with a snapshot every kEvery keyframes, killed after step kKillAt.
struct KilledWalk {
  std::string dir;
  std::uint64_t durable = 0, generation = 0, written = 0, removed = 0;
  std::vector<std::vector<std::uint8_t>> exported;
  std::uint64_t keyframes = 0;
  std::uint32_t peer_version = 0;
};

KilledWalk WalkAndKill(const char* name, const core::Walk& walk) {
  KilledWalk k;
  k.dir = FreshDir(name);
  Robot robot(k.dir, kEvery);
  EXPECT_TRUE(robot.checkpoint != nullptr);
  for (std::size_t i = 0; i < kKillAt; ++i) robot.Step(walk, i);
  const CheckpointStats s = robot.checkpoint->stats();
  k.durable = s.durable_generation;
  k.generation = s.generation;
  k.written = s.snapshots_written;
  k.removed = s.files_removed;
  EXPECT_EQ(s.snapshot_failures, 0u) << s.last_failure;
  EXPECT_EQ(s.journal_errors, 0u);
  k.exported = robot.Exported();
  k.keyframes = robot.mapper.stats().keyframes;
  k.peer_version = robot.peer_version_;
  robot.Kill();
  return k;
}

TEST(Checkpoint, AKilledRobotRestartsFromItsNewestSnapshotAndMapsTheRestAsTheLiveOne) {
  const core::Walk walk(static_cast<int>(kSteps));
  // The robot that is never killed.
  const std::string live_dir = FreshDir("live");
  Robot live(live_dir, kEvery);
  ASSERT_NE(live.checkpoint, nullptr);
  for (std::size_t i = 0; i < kKillAt; ++i) ASSERT_NO_FATAL_FAILURE(live.Step(walk, i));
  const KilledWalk killed = WalkAndKill("killed", walk);
  ASSERT_FALSE(HasFailure());
  // Several generations went by; each durable snapshot removed what lay below the one before.
  EXPECT_GE(killed.written, 3u);
  EXPECT_GE(killed.durable, 3u);
  EXPECT_GT(killed.removed, 0u);
  const std::vector<std::string> files = Files(killed.dir);
  for (const std::string& f : files) {
    bool snapshot = false;
    std::uint64_t g = 0;
    ASSERT_TRUE(CheckpointGeneration(f, snapshot, g)) << f;
    EXPECT_GE(g, killed.durable - 1) << f << ": below the previous durable snapshot";
  }

  Robot restarted(killed.dir, kEvery);
  ASSERT_NE(restarted.checkpoint, nullptr) << restarted.open_error.detail;
  const CheckpointRestore& r = restarted.restored;
  EXPECT_TRUE(r.from_snapshot);
  EXPECT_EQ(r.snapshot_generation, killed.durable);
  EXPECT_TRUE(r.set_aside.empty());
  EXPECT_EQ(r.journals, killed.generation - killed.durable + 1);
  EXPECT_LT(r.replayed.scans, 2 * kEvery);  // only the keyframes since the snapshot
  // Exactly the one message that came between the journal's switch and the session's capture
  // was skipped (the snapshot held it); those after it were replayed.
  EXPECT_EQ(r.messages_skipped, 1u);
  EXPECT_GE(r.replayed.messages, 2u);
  EXPECT_EQ(restarted.mapper.stats().keyframes, killed.keyframes);
  // The session holds what the live one held: the peer message that came between the switch
  // and the capture once, the ones after it replayed.
  EXPECT_EQ(restarted.Exported(), killed.exported);
  EXPECT_EQ(restarted.Exported(), live.Exported());

  // Both go on; the restarted one's map stays with the live one's (the journal keeps points to
  // the millimetre: the keyframes since the snapshot are rebuilt from rounded points).
  restarted.peer_version_ = live.peer_version_;
  for (std::size_t i = kKillAt; i < kSteps; ++i) {
    ASSERT_NO_FATAL_FAILURE(live.Step(walk, i));
    ASSERT_NO_FATAL_FAILURE(restarted.Step(walk, i));
  }
  ASSERT_TRUE(live.mapper.Finish());
  ASSERT_TRUE(restarted.mapper.Finish());
  EXPECT_EQ(live.mapper.stats().keyframes, restarted.mapper.stats().keyframes);
  const double gap = LargestGap(live.mapper, restarted.mapper);
  std::printf("restarted vs live: %.2f mm at most over %llu keyframes\n", gap * 1e3,
              static_cast<unsigned long long>(live.mapper.stats().keyframes));
  EXPECT_LT(gap, 0.005);
  fs::remove_all(killed.dir);
  fs::remove_all(live_dir);
}

TEST(Checkpoint, ASnapshotThatDoesNotCheckIsSetAsideAndTheOneBeforeIsUsed) {
  const core::Walk walk(static_cast<int>(kSteps));
  const KilledWalk killed = WalkAndKill("corrupt", walk);
  ASSERT_FALSE(HasFailure());
  ASSERT_GE(killed.durable, 2u);
  // A bit flipped in the newest snapshot (a bad sector).
  const std::string newest = killed.dir + "/snapshot." + std::to_string(killed.durable) + ".bin";
  {
    std::fstream f(newest, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(1000);
    char c = 0;
    f.read(&c, 1);
    f.seekp(1000);
    c ^= 0x20;
    f.write(&c, 1);
  }
  Robot restarted(killed.dir, kEvery);
  ASSERT_NE(restarted.checkpoint, nullptr) << restarted.open_error.detail;
  const CheckpointRestore& r = restarted.restored;
  ASSERT_EQ(r.set_aside.size(), 1u);
  EXPECT_NE(r.set_aside[0].find("CRC"), std::string::npos) << r.set_aside[0];
  EXPECT_TRUE(fs::exists(newest + ".dropped"));
  EXPECT_TRUE(r.from_snapshot);
  EXPECT_EQ(r.snapshot_generation, killed.durable - 1);
  // The journals from the older snapshot on carry the robot to where it was.
  EXPECT_EQ(restarted.mapper.stats().keyframes, killed.keyframes);
  EXPECT_EQ(restarted.Exported(), killed.exported);
  fs::remove_all(killed.dir);
}

// The offsets of a journal's records (after its header line).
std::vector<std::pair<std::size_t, std::uint8_t>> Records(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  std::vector<std::pair<std::size_t, std::uint8_t>> out;
  std::size_t at = bytes.find('\n') + 1;
  while (at + 12 <= bytes.size()) {
    std::uint32_t length = 0;
    std::memcpy(&length, bytes.data() + at + 4, 4);
    out.emplace_back(at, static_cast<std::uint8_t>(bytes[at]));
    at += 12 + length;
  }
  return out;
}

// A journal that lost its last keyframe at a record boundary (it reads as complete) while the
// next one, which continues it from further on, is whole: the restart stops at the hole and
// sets the next one aside, never replaying past a gap.
TEST(Checkpoint, AJournalThatDoesNotContinueTheOneBeforeWhereItEndedIsSetAside) {
  const core::Walk walk(static_cast<int>(kSteps));
  const KilledWalk killed = WalkAndKill("hole", walk);
  ASSERT_FALSE(HasFailure());
  ASSERT_GE(killed.durable, 2u);
  ASSERT_EQ(killed.generation, killed.durable);
  // The newest snapshot unusable, so the restart goes through the journal before it.
  const std::string newest = killed.dir + "/snapshot." + std::to_string(killed.durable) + ".bin";
  fs::resize_file(newest, fs::file_size(newest) - 1);
  const std::string older = killed.dir + "/journal." + std::to_string(killed.durable - 1) + ".bin";
  const auto records = Records(older);
  std::size_t cut = 0;
  for (const auto& [at, type] : records)
    if (type == static_cast<std::uint8_t>(JournalRecord::kMotion)) cut = at;  // the last keyframe's
  ASSERT_GT(cut, 0u);
  fs::resize_file(older, cut);

  Robot restarted(killed.dir, kEvery);
  ASSERT_NE(restarted.checkpoint, nullptr) << restarted.open_error.detail;
  const CheckpointRestore& r = restarted.restored;
  EXPECT_EQ(r.snapshot_generation, killed.durable - 1);
  EXPECT_EQ(r.journals, 1u);
  bool hole = false;
  for (const std::string& why : r.set_aside) hole = hole || why.find("does not continue") != std::string::npos;
  EXPECT_TRUE(hole);
  EXPECT_TRUE(fs::exists(killed.dir + "/journal." + std::to_string(killed.durable) + ".bin.dropped"));
  // The prefix: everything up to the lost keyframe, nothing after it.
  EXPECT_LT(restarted.mapper.stats().keyframes, killed.keyframes);
  EXPECT_GT(restarted.mapper.stats().keyframes, 0u);
  fs::remove_all(killed.dir);
}

// The snapshot's journal lost the peer message it counted (cut after its first record): the
// restart takes the message from the snapshot and goes on in a new generation's journal, so
// that what it journals is not skipped at the next restart, which finds the robot as it was.
TEST(Checkpoint, AJournalShortOfTheMessagesItsSnapshotCountedIsLeftForANewOne) {
  const core::Walk walk(static_cast<int>(kSteps));
  const KilledWalk killed = WalkAndKill("short", walk);
  ASSERT_FALSE(HasFailure());
  const std::string journal = killed.dir + "/journal." + std::to_string(killed.durable) + ".bin";
  const auto records = Records(journal);
  ASSERT_GE(records.size(), 2u);
  ASSERT_EQ(records[0].second, static_cast<std::uint8_t>(JournalRecord::kContinues));
  fs::resize_file(journal, records[1].first);

  std::vector<std::vector<std::uint8_t>> exported;
  std::uint64_t keyframes = 0;
  {
    Robot first(killed.dir, kEvery);
    ASSERT_NE(first.checkpoint, nullptr) << first.open_error.detail;
    EXPECT_EQ(first.restored.messages_skipped, 0u);
    bool noted = false;
    for (const std::string& why : first.restored.set_aside)
      noted = noted || why.find("fewer peer messages") != std::string::npos;
    EXPECT_TRUE(noted);
    EXPECT_EQ(first.checkpoint->stats().generation, killed.durable + 1);
    first.peer_version_ = killed.peer_version;
    for (std::size_t i = kKillAt; i < kKillAt + 3; ++i) ASSERT_NO_FATAL_FAILURE(first.Step(walk, i));
    first.Peer();
    exported = first.Exported();
    keyframes = first.mapper.stats().keyframes;
  }
  Robot second(killed.dir, kEvery);
  ASSERT_NE(second.checkpoint, nullptr) << second.open_error.detail;
  EXPECT_TRUE(second.restored.set_aside.empty());
  EXPECT_EQ(second.restored.journals, 2u);
  EXPECT_EQ(second.mapper.stats().keyframes, keyframes);
  EXPECT_EQ(second.Exported(), exported);
  fs::remove_all(killed.dir);
}

TEST(Checkpoint, AnotherRobotsFolderIsRefusedAndOtherMapperSettingsStartAfresh) {
  const core::Walk walk(static_cast<int>(kSteps));
  const KilledWalk killed = WalkAndKill("settings", walk);
  ASSERT_FALSE(HasFailure());
  {
    Robot other(killed.dir, kEvery, 7, 9);
    EXPECT_EQ(other.checkpoint, nullptr);
    EXPECT_EQ(other.open_error.code, Errc::kInvalidConfig);
  }
  // Other mapper settings: no snapshot is loaded, journal.bin was removed long ago, so the robot
  // starts empty and every file is kept aside for a look, none read again.
  Robot changed(killed.dir, kEvery, 8);
  ASSERT_NE(changed.checkpoint, nullptr) << changed.open_error.detail;
  EXPECT_FALSE(changed.restored.anything());
  EXPECT_EQ(changed.mapper.stats().keyframes, 0u);
  EXPECT_GE(changed.restored.set_aside.size(), 3u);
  for (const std::string& why : changed.restored.set_aside) std::printf("set aside: %s\n", why.c_str());
  fs::remove_all(killed.dir);
}

// ParseCheckpoint (checkpoint_file.hpp) allocates nothing: a whole snapshot file checked and
// parsed, one with a flipped byte refused, another robot's refused.
TEST(Checkpoint, ParsingASnapshotFileAllocatesNothing) {
  const core::Walk walk(static_cast<int>(kSteps));
  const KilledWalk killed = WalkAndKill("parse", walk);
  ASSERT_FALSE(HasFailure());
  std::string newest;
  std::uint64_t newest_generation = 0;
  for (const auto& entry : fs::directory_iterator(killed.dir)) {
    bool is_snapshot = false;
    std::uint64_t generation = 0;
    const std::string name = entry.path().filename().string();
    if (CheckpointGeneration(name, is_snapshot, generation) && is_snapshot && generation > newest_generation) {
      newest = entry.path().string();
      newest_generation = generation;
    }
  }
  ASSERT_FALSE(newest.empty()) << "no snapshot written";
  std::ifstream in(newest, std::ios::binary);
  const std::vector<std::uint8_t> file((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::vector<std::uint8_t> flipped = file;
  flipped[flipped.size() / 2] ^= 0x40;
  bool parsed = false, refused = false, other_refused = false;
  std::uint32_t messages = 0;
  {
    test::AllocationScope scope;
    const auto p = ParseCheckpoint(file, 1);
    parsed = p.has_value() && !p->mapper.empty();
    if (p) messages = p->session_messages;
    refused = !ParseCheckpoint(flipped, 1).has_value();
    const auto other = ParseCheckpoint(file, 2);
    other_refused = !other.has_value() && other.error().code == Errc::kInvalidConfig;
    EXPECT_EQ(scope.allocations(), 0u);
  }
  EXPECT_TRUE(parsed);
  EXPECT_GT(messages, 0u);
  EXPECT_TRUE(refused);
  EXPECT_TRUE(other_refused);
  fs::remove_all(killed.dir);
}

TEST(Checkpoint, WithoutGenerationsTheJournalAloneRestoresTheRobot) {
  const core::Walk walk(static_cast<int>(kSteps));
  const std::string dir = FreshDir("journal_only");
  std::uint64_t keyframes = 0;
  std::vector<std::vector<std::uint8_t>> exported;
  {
    Robot robot(dir, 0);
    ASSERT_NE(robot.checkpoint, nullptr);
    for (std::size_t i = 0; i < 12; ++i) ASSERT_NO_FATAL_FAILURE(robot.Step(walk, i));
    keyframes = robot.mapper.stats().keyframes;
    exported = robot.Exported();
  }
  EXPECT_EQ(Files(dir), std::vector<std::string>{"journal.bin"});
  Robot restarted(dir, 0);
  ASSERT_NE(restarted.checkpoint, nullptr);
  EXPECT_FALSE(restarted.restored.from_snapshot);
  EXPECT_EQ(restarted.restored.journals, 1u);
  EXPECT_EQ(restarted.mapper.stats().keyframes, keyframes);
  EXPECT_EQ(restarted.Exported(), exported);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace msgraphs::runtime
