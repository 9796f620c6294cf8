// SPDX-License-Identifier: MIT
// The checkpoint journal: records round-trip, a torn tail is cut and appended after, another
// robot's journal is refused.
#include "msgraphs/runtime/pipeline/journal.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>

namespace msgraphs::runtime {
namespace {

struct Collect final : JournalSink {
  std::vector<double> odometry;
  std::vector<std::vector<Eigen::Vector3f>> scans;
  std::vector<std::vector<float>> times;
  std::vector<std::size_t> priors;
  int finishes = 0;
  std::vector<std::vector<std::uint8_t>> messages;
  void OnOdometry(double t, const Eigen::Isometry3d&) override { odometry.push_back(t); }
  void OnScan(std::span<const Eigen::Vector3f> p,
              std::span<const float> t,
              double,
              double) override {
    scans.emplace_back(p.begin(), p.end());
    times.emplace_back(t.begin(), t.end());
  }
  void OnPriors(std::span<const core::PlanePrior> p) override { priors.push_back(p.size()); }
  void OnFinish() override { ++finishes; }
  void OnMessage(core::CollabMessageType, std::span<const std::uint8_t> b) override {
    messages.emplace_back(b.begin(), b.end());
  }
  std::vector<std::pair<double, bool>> motions;
  Eigen::Isometry3d last_motion = Eigen::Isometry3d::Identity();
  void OnMotion(double end_s, const Eigen::Isometry3d& T, bool tracked) override {
    motions.emplace_back(end_s, tracked);
    last_motion = T;
  }
};

std::string TempPath() {
  return (std::filesystem::temp_directory_path() /
          ("msgraphs_journal_" + std::to_string(::getpid())))
      .string();
}

TEST(Journal, RoundTripsEveryRecordWithinItsResolution) {
  const std::string path = TempPath();
  std::filesystem::remove(path);
  {
    auto w = JournalWriter::Open(path, 3, 0);
    ASSERT_TRUE(w);
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() << 1, 2, 3;
    ASSERT_TRUE(w->Odometry(10.5, T));
    const std::vector<Eigen::Vector3f> points = {
        {1.2344f, -3.0f, 0.5f}, {30.0f, 0, 0}, {0.1f, 0.2f, 0.3f}};
    const std::vector<float> times = {0.0f, 0.05f, 0.099f};
    ASSERT_TRUE(w->Scan(points, times, 10.0, 10.1, 25.0f));  // the 30 m point is beyond range
    core::PlanePrior prior;
    prior.plane = 4;
    ASSERT_TRUE(w->Priors(std::span(&prior, 1)));
    ASSERT_TRUE(w->Finish());
    const std::uint8_t bytes[] = {1, 2, 3};
    ASSERT_TRUE(w->Message(core::CollabMessageType::kRoomDescriptor, bytes));
    Eigen::Isometry3d motion(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()));
    motion.translation() << 1.05, -0.02, 0.001;
    ASSERT_TRUE(w->Motion(11.1, motion, true));
    ASSERT_TRUE(w->Sync());
  }
  Collect c;
  auto r = ReplayJournal(path, 3, c);
  ASSERT_TRUE(r);
  EXPECT_TRUE(r->stopped.empty()) << r->stopped;
  EXPECT_EQ(r->records, 6u);
  ASSERT_EQ(c.motions.size(), 1u);
  EXPECT_DOUBLE_EQ(c.motions[0].first, 11.1);
  EXPECT_TRUE(c.motions[0].second);
  EXPECT_NEAR(c.last_motion.translation().x(), 1.05, 1e-12);  // f64: exact
  EXPECT_EQ(r->motions, 1u);
  ASSERT_EQ(c.scans.size(), 1u);
  ASSERT_EQ(c.scans[0].size(), 2u);
  EXPECT_NEAR(c.scans[0][0].x(), 1.2344f, 0.0006f);  // millimetres
  EXPECT_NEAR(c.times[0][1], 0.099f, 3e-6f);         // 4 us steps
  EXPECT_EQ(c.odometry, std::vector<double>{10.5});
  EXPECT_EQ(c.priors, std::vector<std::size_t>{1});
  EXPECT_EQ(c.finishes, 1);
  EXPECT_EQ(c.messages.size(), 1u);
  EXPECT_DOUBLE_EQ(r->last_scan_end_s, 10.1);

  // Another robot's checkpoint folder is refused, not mixed in.
  Collect other;
  EXPECT_EQ(ReplayJournal(path, 4, other).error().code, Errc::kInvalidConfig);
  std::filesystem::remove(path);
}

TEST(Journal, TornTailIsCutAndAppendedAfter) {
  const std::string path = TempPath();
  std::filesystem::remove(path);
  {
    auto w = JournalWriter::Open(path, 1, 0);
    ASSERT_TRUE(w);
    for (int i = 0; i < 3; ++i) ASSERT_TRUE(w->Odometry(i, Eigen::Isometry3d::Identity()));
  }
  // A process killed in the middle of a record, or a power cut after a partial write.
  std::filesystem::resize_file(path, std::filesystem::file_size(path) - 10);
  Collect c;
  auto r = ReplayJournal(path, 1, c);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->records, 2u);
  EXPECT_EQ(r->stopped, "torn record at the end");
  {
    auto w = JournalWriter::Open(path, 1, r->valid_bytes);
    ASSERT_TRUE(w);
    ASSERT_TRUE(w->Odometry(7, Eigen::Isometry3d::Identity()));
  }
  Collect again;
  r = ReplayJournal(path, 1, again);
  ASSERT_TRUE(r);
  EXPECT_TRUE(r->stopped.empty());
  EXPECT_EQ(again.odometry, (std::vector<double>{0, 1, 7}));
  // A flipped byte inside a record stops the replay there, with the reason.
  {
    std::FILE* f = std::fopen(path.c_str(), "r+b");
    std::fseek(f, -3, SEEK_END);
    std::fputc(0x5A, f);
    std::fclose(f);
  }
  Collect corrupt;
  r = ReplayJournal(path, 1, corrupt);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->stopped, "record CRC mismatch");
  EXPECT_EQ(corrupt.odometry.size(), 2u);
  std::filesystem::remove(path);
}

TEST(Journal, MissingFileIsAFreshStart) {
  Collect c;
  auto r = ReplayJournal("/nonexistent/journal.bin", 1, c);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->records, 0u);
}

}  // namespace
}  // namespace msgraphs::runtime
