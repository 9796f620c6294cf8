// SPDX-License-Identifier: MIT
// The mapper's snapshot (LocalMapper::Save / Load): a mapper loaded from a snapshot taken after
// a keyframe maps the rest of the walk bit for bit as the one it was saved from, with the full
// solve on the spot and in the background; saving allocates nothing; bytes that are not a
// whole snapshot are refused with the mapper unchanged.
#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "alloc_counter.hpp"
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
};

// The 45-step walk (three laps: loops, sparsification at 64 keyframes, a full cloud store).
// `save_from`: after that step and every 11 steps from it, the mapper is saved, loaded into a
// new one, and the walk goes on with the new one (0: never).
WalkResult WalkOf(std::size_t lag, std::size_t save_from) {
  const LocalMapperConfig config = SnapshotConfig(lag);
  auto mapper = std::make_unique<LocalMapper>();
  EXPECT_TRUE(mapper->Init(config));
  const Walk walk(45);
  std::vector<float> times(20000, 0.1f);
  WalkResult out;
  bool save_due = false;
  for (std::size_t i = 0; i < walk.truth.size(); ++i) {
    EXPECT_TRUE(FeedStep(*mapper, config, walk, i, times));
    if (save_from > 0 && i >= save_from && (i - save_from) % 11 == 0) save_due = true;
    // As the node: at the first keyframe with no background solve pending.
    if (!save_due || mapper->background_solve() != nullptr) continue;
    std::vector<std::uint8_t> bytes(mapper->SnapshotBytes());
    Expected<std::size_t> n = Error{Errc::kInvalidArgument};
    {
      test::AllocationScope scope;
      n = mapper->Save(bytes);
      out.save_allocations += scope.allocations();
    }
    if (!n && n.error().code == Errc::kWouldBlock) continue;  // applied at a later keyframe
    EXPECT_TRUE(n);
    if (!n) return out;
    bytes.resize(*n);
    auto loaded = std::make_unique<LocalMapper>();
    EXPECT_TRUE(loaded->Init(config));
    EXPECT_TRUE(loaded->Load(bytes));
    std::vector<std::uint8_t> again(loaded->SnapshotBytes());
    auto m = loaded->Save(again);
    EXPECT_TRUE(m);
    again.resize(m ? *m : 0);
    EXPECT_EQ(again, bytes) << "saved again after step " << i;
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
  // The good bytes load, and the mapper goes on.
  ASSERT_TRUE(other.Load(good));
  EXPECT_EQ(other.stats().keyframes, 20u);
  EXPECT_TRUE(FeedStep(other, config, walk, 20, times));
}

}  // namespace
}  // namespace msgraphs::core
