// SPDX-License-Identifier: MIT
// The mapper's snapshot (LocalMapper::Save / Load): a mapper loaded from a snapshot taken after
// a keyframe maps the rest of the walk bit for bit as the one it was saved from, with the full
// solve on the spot and in the background; saving allocates nothing; bytes that are not a
// whole snapshot are refused with the mapper unchanged.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <memory>
#include <random>
#include <vector>

#include "alloc_counter.hpp"
#include "msgraphs/base/crc32.hpp"
#include "box_room_walk.hpp"
#include "msgraphs/core/slam/local_mapper.hpp"

namespace msgraphs::core {
namespace {

LocalMapperConfig SnapshotConfig(std::size_t lag) {
  LocalMapperConfig config = SmallConfig(64, 256);
  config.cloud_store_points = 150000;  // about 25 clouds: the store evicts within the walk
  config.full_solve_lag_keyframes = lag;
  config.graph.local_max_seconds = 1e9;  // the iteration caps only: never the machine's load
  config.graph.full_max_seconds = 1e9;
  return config;
}

struct WalkResult {
  std::vector<double> values;  // every keyframe's pose and every plane, in slot order
  LocalMapperStats stats;
  std::size_t saves = 0;
  std::uint64_t save_allocations = 0;
  std::size_t loads_that_began_a_solve = 0;
};

// How the walk takes its snapshots: between scans when no solve is pending (Save), or asked
// for and taken by the mapper at a keyframe's end (RequestSnapshot), as the node does.
enum class SaveBy { kSave, kRequest };

// The 45-step walk (three laps: loops, sparsification at 64 keyframes, a full cloud store).
// `save_from`: after that step and every 11 steps from it, the mapper is saved, loaded into a
// new one, and the walk goes on with the new one (0: never).
WalkResult WalkOf(std::size_t lag, std::size_t save_from, SaveBy by = SaveBy::kSave) {
  const LocalMapperConfig config = SnapshotConfig(lag);
  auto mapper = std::make_unique<LocalMapper>();
  EXPECT_TRUE(mapper->Init(config));
  const Walk walk(45);
  std::vector<float> times(20000, 0.1f);
  WalkResult out;
  bool save_due = false;
  std::vector<std::uint8_t> bytes;
  for (std::size_t i = 0; i < walk.truth.size(); ++i) {
    if (by == SaveBy::kRequest && save_due && !mapper->snapshot_requested()) {
      bytes.assign(mapper->SnapshotBytes(), 0);
      test::AllocationScope scope;
      mapper->RequestSnapshot(bytes);
      out.save_allocations += scope.allocations();
    }
    EXPECT_TRUE(FeedStep(*mapper, config, walk, i, times));
    Expected<std::size_t> n = Error{Errc::kInvalidArgument};
    if (save_from > 0 && i >= save_from && (i - save_from) % 11 == 0) save_due = true;
    if (!save_due) continue;
    if (by == SaveBy::kRequest) {
      test::AllocationScope scope;
      auto taken = mapper->TakeSnapshot();
      out.save_allocations += scope.allocations();
      if (!taken) continue;  // no keyframe yet, or a solve pending at each
      n = *taken;
    } else {
      // As the node did before: at the first keyframe with no background solve pending.
      if (mapper->background_solve() != nullptr) continue;
      bytes.assign(mapper->SnapshotBytes(), 0);
      test::AllocationScope scope;
      n = mapper->Save(bytes);
      out.save_allocations += scope.allocations();
      if (!n && n.error().code == Errc::kWouldBlock) continue;  // applied at a later keyframe
    }
    EXPECT_TRUE(n);
    if (!n) return out;
    bytes.resize(*n);
    auto loaded = std::make_unique<LocalMapper>();
    EXPECT_TRUE(loaded->Init(config));
    EXPECT_TRUE(loaded->Load(bytes));
    // Saved again it is the same bytes; a snapshot taken at a keyframe's end may have a solve
    // wanted there, which the load began (as the live mapper did): it cannot be saved again
    // until that solve is applied.
    if (loaded->background_solve() == nullptr) {
      std::vector<std::uint8_t> again(loaded->SnapshotBytes());
      auto m = loaded->Save(again);
      EXPECT_TRUE(m);
      again.resize(m ? *m : 0);
      EXPECT_EQ(again, bytes) << "saved again after step " << i;
    } else {
      ++out.loads_that_began_a_solve;
    }
    mapper = std::move(loaded);
    save_due = false;
    ++out.saves;
  }
  EXPECT_TRUE(mapper->Finish());
  const SGraph& g = mapper->graph();
  for (std::uint32_t k = 0; k < g.keyframe_slots(); ++k) {
    if (!g.keyframe_active(k)) continue;
    const Eigen::Isometry3d T = g.keyframe_pose(k);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) out.values.push_back(T.matrix()(r, c));
  }
  for (std::uint32_t p = 0; p < g.plane_slots(); ++p) {
    const MapPlane plane = g.plane(p);
    for (int a = 0; a < 3; ++a) out.values.push_back(plane.normal[a]);
    out.values.push_back(plane.d);
  }
  out.stats = mapper->stats();
  return out;
}

void ExpectSameWalk(const WalkResult& a, const WalkResult& b) {
  ASSERT_EQ(a.values.size(), b.values.size());
  std::size_t differ = 0;
  for (std::size_t i = 0; i < a.values.size(); ++i) differ += a.values[i] != b.values[i];
  EXPECT_EQ(differ, 0u) << "of " << a.values.size();
  EXPECT_EQ(a.stats.keyframes, b.stats.keyframes);
  EXPECT_EQ(a.stats.loop_closures, b.stats.loop_closures);
  EXPECT_EQ(a.stats.scan_match_accepted, b.stats.scan_match_accepted);
  EXPECT_EQ(a.stats.full_solves, b.stats.full_solves);
}

TEST(LocalMapperSnapshot, ALoadedMapperMapsTheRestOfTheWalkBitForBit) {
  for (std::size_t lag : {std::size_t{0}, std::size_t{5}}) {
    SCOPED_TRACE(lag);
    const WalkResult reference = WalkOf(lag, 0);
    const WalkResult restored = WalkOf(lag, 7);
    ASSERT_FALSE(HasFailure());
    // The walk reached what it is meant to exercise, around the snapshots.
    EXPECT_GE(reference.stats.loop_closures, 3u);
    EXPECT_GE(restored.saves, lag == 0 ? 3u : 1u);  // with lag, a solve is pending most keyframes
    EXPECT_EQ(restored.save_allocations, 0u);
    ExpectSameWalk(reference, restored);
  }
}

// The node's way (runtime's checkpoint): a snapshot asked for is taken by the mapper at the end
// of the next keyframe with no solve pending, between the solve applied there and the next
// begun. A save between scans finds that moment rarely with the solve in the background.
TEST(LocalMapperSnapshot, ASnapshotAskedForIsTakenBetweenSolvesAndTheWalkGoesOnBitForBit) {
  const WalkResult reference = WalkOf(5, 0);
  const WalkResult restored = WalkOf(5, 7, SaveBy::kRequest);
  ASSERT_FALSE(HasFailure());
  EXPECT_GE(restored.saves, 3u);  // steps 7, 18, 29, 40: each served within a few keyframes
  EXPECT_EQ(restored.save_allocations, 0u) << "asking for a snapshot and taking it";
  // Some were taken with a solve wanted and not begun: the load began it, as live.
  EXPECT_GE(restored.loads_that_began_a_solve, 1u);
  ExpectSameWalk(reference, restored);
}

TEST(LocalMapperSnapshot, BytesThatAreNotAWholeSnapshotAreRefusedAndChangeNothing) {
  const LocalMapperConfig config = SnapshotConfig(0);
  LocalMapper mapper;
  ASSERT_TRUE(mapper.Init(config));
  const Walk walk(45);
  std::vector<float> times(20000, 0.1f);
  for (std::size_t i = 0; i < 20; ++i) ASSERT_TRUE(FeedStep(mapper, config, walk, i, times));
  std::vector<std::uint8_t> good(mapper.SnapshotBytes());
  auto n = mapper.Save(good);
  ASSERT_TRUE(n);
  good.resize(*n);
  LocalMapper other;
  ASSERT_TRUE(other.Init(config));
  for (std::size_t i = 0; i < 3; ++i) ASSERT_TRUE(FeedStep(other, config, walk, i, times));
  const auto refused = [&](std::span<const std::uint8_t> bytes) {
    const Status s = other.Load(bytes);
    EXPECT_FALSE(s);
    EXPECT_EQ(other.stats().keyframes, 3u);
    EXPECT_EQ(other.graph().stats().keyframes, 3u);
  };
  refused(std::span(good).first(good.size() - 1));
  refused(std::span(good).first(100));
  for (std::size_t at = 0; at < good.size(); at += good.size() / 37) {
    std::vector<std::uint8_t> bad = good;
    bad[at] ^= 0x01;
    refused(bad);
  }
  // Another graph config: refused by the graph's part, nothing changed.
  LocalMapperConfig bigger = config;
  bigger.graph.huber_plane = 3.0;
  LocalMapper third;
  ASSERT_TRUE(third.Init(bigger));
  for (std::size_t i = 0; i < 3; ++i) ASSERT_TRUE(FeedStep(third, bigger, walk, i, times));
  EXPECT_FALSE(third.Load(good));
  EXPECT_EQ(third.stats().keyframes, 3u);
  // Sealed later (the node's SLAM thread copies, its writer thread seals): unsealed, the bytes
  // are refused; sealed, they are the bytes sealed at once. Neither step allocates.
  std::vector<std::uint8_t> later(mapper.SnapshotBytes());
  std::uint64_t allocations = 0;
  Expected<std::size_t> later_n = std::size_t{0};
  {
    test::AllocationScope scope;
    later_n = mapper.Save(later, SnapshotSeal::kLater);
    allocations = scope.allocations();
  }
  ASSERT_TRUE(later_n);
  ASSERT_EQ(*later_n, good.size());
  later.resize(*later_n);
  EXPECT_NE(later, good);
  refused(later);
  {
    test::AllocationScope scope;
    EXPECT_TRUE(LocalMapper::SealSnapshot(later));
    allocations += scope.allocations();
  }
  EXPECT_EQ(allocations, 0u);
  EXPECT_EQ(later, good);
  // Bytes that are not a whole mapper snapshot are refused and left as they were: cut short
  // (within the header, or anywhere after it), or a graph length too short for the graph's own
  // header (20-23 bytes hold its magic and length but not its CRC).
  const auto refused_seal = [](std::vector<std::uint8_t> bytes) {
    const std::vector<std::uint8_t> before = bytes;
    EXPECT_FALSE(LocalMapper::SealSnapshot(bytes)) << bytes.size();
    EXPECT_EQ(bytes, before);
  };
  for (std::size_t cut : {std::size_t{0}, std::size_t{20}, std::size_t{22}, std::size_t{30}, later.size() - 1})
    refused_seal(std::vector<std::uint8_t>(later.begin(), later.begin() + static_cast<std::ptrdiff_t>(cut)));
  for (std::uint64_t graph_bytes : {std::uint64_t{20}, std::uint64_t{23}, std::uint64_t{later.size()}}) {
    std::vector<std::uint8_t> bad = later;
    bad[kSnapshotHeaderBytes - 1] ^= 0x5A;  // unsealed again, so a refusal that wrote shows
    std::memcpy(bad.data() + kSnapshotHeaderBytes, &graph_bytes, sizeof graph_bytes);
    refused_seal(bad);
  }
  // The good bytes load, and the mapper goes on.
  ASSERT_TRUE(other.Load(good));
  EXPECT_EQ(other.stats().keyframes, 20u);
  EXPECT_TRUE(FeedStep(other, config, walk, 20, times));
}

// Bytes of the mapper's parts changed before the snapshot's CRC was taken (a writer's bug or
// a file made to pass): a load reads and writes within the stores whatever they hold, and so do
// the scans after it, new priors and Finish (the sanitizer builds run this); a refused load
// leaves the mapper as Init left it, able to map.
TEST(LocalMapperSnapshot, ALoadAndTheScansAfterItStayWithinTheStoresWhateverThePartsHold) {
  const LocalMapperConfig config = SnapshotConfig(0);
  const Walk walk(45);
  std::vector<float> times(20000, 0.1f);
  std::vector<std::uint8_t> good;
  {
    LocalMapper mapper;
    ASSERT_TRUE(mapper.Init(config));
    for (std::size_t i = 0; i < 30; ++i) ASSERT_TRUE(FeedStep(mapper, config, walk, i, times));
    good.resize(mapper.SnapshotBytes());
    auto n = mapper.Save(good);
    ASSERT_TRUE(n);
    good.resize(*n);
  }
  constexpr std::size_t kHeader = 24;
  std::uint64_t graph_bytes = 0;
  std::memcpy(&graph_bytes, good.data() + kHeader, 8);
  const std::size_t parts_at = kHeader + 8 + static_cast<std::size_t>(graph_bytes);
  ASSERT_LT(parts_at, good.size());
  // Half the changes go to bytes that look like counts, indices or flags in the last 4 kB: the
  // mapper's own fields and the end of its per-keyframe odometry (elsewhere the grid's and the
  // clouds' cells are mostly small values too, and changing them is harmless). The parts'
  // structural refusals are tested one by one (snapshot_parts_test.cpp).
  std::vector<std::size_t> small;
  for (std::size_t i = std::max(parts_at, good.size() - 4096); i < good.size(); ++i)
    if (good[i] <= 8 || good[i] == 0xFF) small.push_back(i);
  std::mt19937 rng(23);
  std::uniform_int_distribution<std::size_t> at(parts_at, good.size() - 1);
  std::uniform_int_distribution<std::size_t> at_small(0, small.size() - 1);
  std::uniform_int_distribution<int> byte(0, 255);
  std::size_t loaded = 0, refused = 0;
  LocalMapper mapper;
  for (int trial = 0; trial < 40; ++trial) {
    std::vector<std::uint8_t> bad = good;
    for (int c = 0; c < 1 + trial % 3; ++c) {
      const std::size_t i = trial % 2 == 0 ? at(rng) : small[at_small(rng)];
      bad[i] = static_cast<std::uint8_t>(trial % 2 == 0 ? byte(rng) : byte(rng) % 4);
    }
    const std::uint32_t crc = Crc32(std::span(bad).subspan(kHeader));
    std::memcpy(bad.data() + 20, &crc, 4);
    ASSERT_TRUE(mapper.Init(config));
    if (mapper.Load(bad)) {
      ++loaded;
    } else {
      ++refused;
      EXPECT_EQ(mapper.stats().keyframes, 0u);
      EXPECT_EQ(mapper.graph().stats().keyframes, 0u);
    }
    // The walk goes on from where the snapshot was (results unjudged: the map may be garbage).
    for (std::size_t i = 30; i < 33; ++i) {
      const double t = 10.0 + static_cast<double>(i);
      static_cast<void>(mapper.AddOdometry(t - 0.15, walk.odometry[i]));
      static_cast<void>(mapper.AddOdometry(t + 0.05, walk.odometry[i]));
      const auto points = ScanAt(walk.truth[i], config, static_cast<std::uint32_t>(i + 1));
      static_cast<void>(mapper.AddScan({points, times, t - 0.1, t}));
    }
    static_cast<void>(mapper.SetPlanePriors({}));
    static_cast<void>(mapper.Finish());
  }
  // Random changes land almost always in values (cells, points, poses) that load: what this
  // shows is that the scans after any such load stay within the stores, which only the
  // sanitizer builds can judge.
  std::printf("changed mapper snapshots: %zu loaded, %zu refused\n", loaded, refused);
  EXPECT_GT(loaded, 0u);
}

}  // namespace
}  // namespace msgraphs::core
