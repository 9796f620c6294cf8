// SPDX-License-Identifier: MIT
// The S-Graph's snapshot (SGraph::Save / Load): a graph loaded from a snapshot goes on bit for
// bit as the one it was saved from; saving allocates nothing; bytes that are not a whole
// snapshot of this graph's config are refused with the graph unchanged, and a load never reads
// or writes past a store, whatever the bytes.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <cstring>
#include <memory>
#include <random>
#include <thread>
#include <vector>

#include "alloc_counter.hpp"
#include "mixed_mission.hpp"
#include "msgraphs/base/crc32.hpp"
#include "msgraphs/core/graph/s_graph.hpp"

namespace msgraphs::core {
namespace {

using namespace sgraph_test;  // NOLINT(google-build-using-namespace): test fixtures

std::vector<std::uint8_t> SaveOf(const SGraph& g) {
  std::vector<std::uint8_t> bytes(g.SnapshotBytes());
  auto n = g.Save(bytes);
  EXPECT_TRUE(n);
  bytes.resize(n ? *n : 0);
  return bytes;
}

TEST(SGraphSnapshot, ALoadedGraphGoesOnBitForBitAsTheOneItWasSavedFrom) {
  const MissionOutcome reference = RunMixedMission({});
  ASSERT_FALSE(HasFailure());
  std::size_t loads = 0, save_allocations = 0;
  const MissionOutcome restored = RunMixedMission([&](std::unique_ptr<SGraph>& g, std::size_t i) {
    // Before sparsification, after it began, after the background solve and the prior's
    // replacement: each time the node would restart from a snapshot.
    if (i != 60 && i != 125 && i != 140) return;
    std::vector<std::uint8_t> bytes(g->SnapshotBytes());
    Expected<std::size_t> n = Error{Errc::kInvalidArgument};
    {
      test::AllocationScope scope;
      n = g->Save(bytes);
      save_allocations += scope.allocations();
    }
    ASSERT_TRUE(n);
    bytes.resize(*n);
    auto loaded = std::make_unique<SGraph>();
    ASSERT_TRUE(loaded->Init(MixedMissionConfig()));
    ASSERT_TRUE(loaded->Load(bytes));
    // Saved again, the same bytes: nothing was lost or changed on the way.
    EXPECT_EQ(SaveOf(*loaded), bytes) << i;
    g = std::move(loaded);
    ++loads;
  });
  ASSERT_FALSE(HasFailure());
  EXPECT_EQ(loads, 3u);
  EXPECT_EQ(save_allocations, 0u);
  EXPECT_GT(reference.stats.sparsified, 50u);
  ExpectSameOutcome(reference, restored);
}

// A graph with every kind of record, saved.
std::vector<std::uint8_t> MissionSnapshot(std::size_t at) {
  std::vector<std::uint8_t> bytes;
  RunMixedMission([&](std::unique_ptr<SGraph>& g, std::size_t i) {
    if (i == at) bytes = SaveOf(*g);
  });
  return bytes;
}

// A graph with one keyframe, to see that a refused load leaves it as it was.
void OneKeyframe(SGraph& g) {
  ASSERT_TRUE(g.Init(MixedMissionConfig()));
  ASSERT_TRUE(g.AddKeyframe(0.0, Eigen::Isometry3d::Identity()));
}

TEST(SGraphSnapshot, BytesThatAreNotAWholeSnapshotOfThisConfigAreRefusedAndChangeNothing) {
  const std::vector<std::uint8_t> good = MissionSnapshot(150);
  ASSERT_GT(good.size(), 1000u);
  SGraph g;
  ASSERT_NO_FATAL_FAILURE(OneKeyframe(g));
  const auto refused = [&](std::span<const std::uint8_t> bytes) {
    const Status s = g.Load(bytes);
    EXPECT_FALSE(s);
    EXPECT_EQ(g.stats().keyframes, 1u);  // unchanged
    return !s;
  };
  // Truncated anywhere, or with a byte more.
  for (std::size_t n : {std::size_t{0}, std::size_t{10}, std::size_t{24}, good.size() / 2,
                        good.size() - 1})
    EXPECT_TRUE(refused(std::span(good).first(n))) << n;
  std::vector<std::uint8_t> longer = good;
  longer.push_back(0);
  EXPECT_TRUE(refused(longer));
  // Any byte changed: the magic, the version, the length, the CRC, the payload.
  for (std::size_t at = 0; at < good.size(); at += 97) {
    std::vector<std::uint8_t> bad = good;
    bad[at] ^= 0x20;
    EXPECT_TRUE(refused(bad)) << at;
  }
  // Made with another config.
  SGraphConfig other = MixedMissionConfig();
  other.huber_plane = 3.0;
  SGraph h;
  ASSERT_TRUE(h.Init(other));
  ASSERT_TRUE(h.AddKeyframe(0.0, Eigen::Isometry3d::Identity()));
  const Status s = h.Load(good);
  ASSERT_FALSE(s);
  EXPECT_STREQ(s.error().detail, "s-graph snapshot: made with another graph config");
  EXPECT_EQ(h.stats().keyframes, 1u);
  // The good bytes load.
  EXPECT_TRUE(g.Load(good));
  EXPECT_EQ(g.stats().keyframes, 120u);
}

// What a graph is asked to do after a load: every path that walks its links and counts.
void Exercise(SGraph& g) {
  std::uint32_t newest = 0;
  bool have_newest = false;
  for (std::uint32_t k = g.FirstKeyframe(); k != SGraph::kNoKeyframe; k = g.NextKeyframe(k)) {
    newest = k;
    have_newest = true;
  }
  for (int i = 0; i < 3; ++i) {  // past the store's capacity: sparsification
    auto id = g.AddKeyframe(1e9 + i, Eigen::Isometry3d::Identity());
    if (id && have_newest) {
      static_cast<void>(g.AddRelativePose(newest, *id, Eigen::Isometry3d::Identity(),
                                          OdometryInformation(), RelativePoseKind::kOdometry));
    }
    if (id) {
      newest = *id;
      have_newest = true;
    }
  }
  static_cast<void>(g.Solve(SolveKind::kLocal));
  static_cast<void>(g.Solve(SolveKind::kFull));
  SGraphSolveJob job;
  if (job.Init(MixedMissionConfig()) && g.BeginFullSolve(job)) {
    job.Complete();
    static_cast<void>(g.ApplyFullSolve(job));
  }
  std::vector<std::uint32_t> planes;
  for (std::uint32_t p = 0; p < g.plane_slots(); ++p) {
    if (have_newest) {
      PlaneMeasurement z;
      z.normal = g.plane(p).normal;
      z.d = g.plane(p).d;
      z.basis_u = z.normal.unitOrthogonal();
      z.basis_v = z.normal.cross(z.basis_u);
      z.covariance = Eigen::Matrix3d::Identity() * 1e-4;
      static_cast<void>(g.AddPlaneObservation(newest, p, z));
    }
    if (g.plane(p).live_observations > 0) planes.push_back(p);
  }
  std::vector<Eigen::Matrix3d> covariances(planes.size());
  static_cast<void>(g.PlaneMarginals(planes, covariances));
  for (std::uint32_t r = 0; r < g.room_slots(); ++r) {
    MapRoom room = g.room(r);
    static_cast<void>(g.UpdateRoom(r, room));
    static_cast<void>(g.RemoveRoom(r));
  }
  for (std::uint32_t f = 0; f < 64; ++f) static_cast<void>(g.RemoveFactor(f));
  for (std::uint32_t k = g.FirstKeyframe(); k != SGraph::kNoKeyframe;) {
    const std::uint32_t next = g.NextKeyframe(k);
    static_cast<void>(g.RemoveKeyframe(k));
    k = next;
  }
  std::vector<std::uint8_t> bytes(g.SnapshotBytes());
  static_cast<void>(g.Save(bytes));
}

// Bytes that pass the CRC but were changed before it was taken (a writer's bug, or a file
// made to pass): a load reads and writes within the stores whatever they hold, and so do the
// graph's calls after it (the sanitizer builds run this). Half the changes are to bytes that
// look like a count, an index, a flag or an enum (small values, or kNone's 0xFF), which the
// structural checks must catch; a refused load leaves the graph empty (as it was, or as Init
// left it) and usable. What a load that passes makes of such bytes is not judged beyond that:
// the CRC is the guard against corruption.
TEST(SGraphSnapshot, ALoadAndTheCallsAfterItStayWithinTheStoresWhateverTheBytesHold) {
  const std::vector<std::uint8_t> good = MissionSnapshot(150);
  ASSERT_GT(good.size(), 1000u);
  constexpr std::size_t kHeader = 24;
  std::vector<std::size_t> small;  // positions of bytes that look structural
  for (std::size_t i = kHeader; i < good.size(); ++i)
    if (good[i] <= 8 || good[i] == 0xFF) small.push_back(i);
  std::mt19937 rng(17);
  std::uniform_int_distribution<std::size_t> at(kHeader, good.size() - 1);
  std::uniform_int_distribution<std::size_t> at_small(0, small.size() - 1);
  std::uniform_int_distribution<int> byte(0, 255);
  const std::array<std::uint8_t, 6> structural{0, 1, 2, 3, 7, 0xFF};
  std::size_t loaded = 0, refused = 0;
  for (int trial = 0; trial < 250; ++trial) {
    std::vector<std::uint8_t> bad = good;
    const int changes = 1 + trial % 3;
    for (int c = 0; c < changes; ++c) {
      if (trial % 2 == 0) {
        bad[at(rng)] = static_cast<std::uint8_t>(byte(rng));
      } else {
        bad[small[at_small(rng)]] = structural[static_cast<std::size_t>(byte(rng)) % structural.size()];
      }
    }
    const std::uint32_t crc = Crc32(std::span(bad).subspan(kHeader));
    std::memcpy(bad.data() + 20, &crc, 4);
    SGraph g;
    ASSERT_TRUE(g.Init(MixedMissionConfig()));
    if (g.Load(bad)) {
      ++loaded;
    } else {
      ++refused;
      EXPECT_EQ(g.stats().keyframes, 0u);
    }
    Exercise(g);
  }
  std::printf("changed snapshots: %zu loaded, %zu refused\n", loaded, refused);
  EXPECT_GT(loaded, 0u);
  EXPECT_GT(refused, 0u);
}

// The node's marginals thread holds a job that borrows the graph's costs across keyframes; the
// checkpoint's snapshot is taken meanwhile. Both only read: the save goes on, the same bytes as
// without the job, while a load (which would free the costs the job evaluates) waits.
TEST(SGraphSnapshot, AMarginalsJobBorrowingDoesNotStopASaveButStopsALoad) {
  std::size_t checked = 0;
  RunMixedMission([&](std::unique_ptr<SGraph>& g, std::size_t i) {
    if (i != 100) return;
    std::vector<std::uint32_t> walls;
    for (std::uint32_t p = 0; p < g->plane_slots() && walls.size() < 8; ++p) {
      const MapPlane plane = g->plane(p);
      if (plane.active && plane.live_observations > 0) walls.push_back(p);
    }
    ASSERT_FALSE(walls.empty());
    const std::vector<std::uint8_t> before = SaveOf(*g);
    SGraphSolveJob job;
    ASSERT_TRUE(job.Init(MixedMissionConfig()));
    ASSERT_TRUE(g->BeginPlaneMarginals(job, walls));  // it borrows from here until Run ends
    EXPECT_EQ(SaveOf(*g), before);
    const Status load = g->Load(before);
    ASSERT_FALSE(load);
    EXPECT_EQ(load.error().code, Errc::kWouldBlock);
    // And while a worker evaluates the borrowed costs (ASan and TSan builds see any race).
    ASSERT_TRUE(job.TryClaim());
    std::vector<std::uint8_t> during(g->SnapshotBytes());
    Expected<std::size_t> n = Error{Errc::kInvalidArgument};
    {
      std::jthread worker([&job] { job.Run(); });
      n = g->Save(during);
    }
    ASSERT_TRUE(n);
    during.resize(*n);
    EXPECT_EQ(during, before);
    ASSERT_TRUE(job.Release());
    ++checked;
  });
  EXPECT_EQ(checked, 1u);
}

TEST(SGraphSnapshot, NoSaveOrLoadWhileAJobBorrowsAndNoneIntoTooSmallABuffer) {
  SGraph g;
  ASSERT_NO_FATAL_FAILURE(OneKeyframe(g));
  std::vector<std::uint8_t> bytes(g.SnapshotBytes());
  std::vector<std::uint8_t> small(64);
  auto too_small = g.Save(small);
  ASSERT_FALSE(too_small);
  EXPECT_EQ(too_small.error().code, Errc::kCapacityExceeded);
  SGraphSolveJob job;
  ASSERT_TRUE(job.Init(MixedMissionConfig()));
  ASSERT_TRUE(g.BeginFullSolve(job));
  auto busy = g.Save(bytes);
  ASSERT_FALSE(busy);
  EXPECT_EQ(busy.error().code, Errc::kWouldBlock);
  const std::vector<std::uint8_t> other = MissionSnapshot(30);
  const Status load_busy = g.Load(other);
  ASSERT_FALSE(load_busy);
  EXPECT_EQ(load_busy.error().code, Errc::kWouldBlock);
  job.Complete();
  ASSERT_TRUE(g.ApplyFullSolve(job));
  auto n = g.Save(bytes);
  ASSERT_TRUE(n);
  EXPECT_LE(*n, g.SnapshotBytes());
  // A graph just loaded saves without allocating too.
  SGraph loaded;
  ASSERT_TRUE(loaded.Init(MixedMissionConfig()));
  ASSERT_TRUE(loaded.Load(other));
  std::vector<std::uint8_t> again(loaded.SnapshotBytes());
  test::AllocationScope scope;
  auto m = loaded.Save(again);
  EXPECT_EQ(scope.allocations(), 0u);
  ASSERT_TRUE(m);
  EXPECT_EQ(*m, other.size());
}

}  // namespace
}  // namespace msgraphs::core
