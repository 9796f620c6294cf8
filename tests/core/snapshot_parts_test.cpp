// SPDX-License-Identifier: MIT
// The mapper's parts in a snapshot, one by one: a part loaded into a fresh one (or one in
// another state) takes the saved state, including what it derives from it (the cover's cell
// from its coarsenings, the grid's origin from the cells it moved), and refuses bytes that
// would make its later calls read or write past its stores.
#include <gtest/gtest.h>

#include <climits>
#include <cstring>
#include <vector>

#include "msgraphs/base/snapshot_archive.hpp"
#include "msgraphs/core/perception/free_space_grid.hpp"
#include "msgraphs/core/slam/cloud_cover_policy.hpp"
#include "msgraphs/core/slam/keyframe_cloud_store.hpp"

namespace msgraphs::core {
namespace {

template <typename Part>
std::vector<std::uint8_t> Saved(const Part& part) {
  std::vector<std::uint8_t> bytes(1 << 24);
  SnapshotWriter w(bytes);
  part.Save(w);
  EXPECT_FALSE(w.failed());
  bytes.resize(w.size());
  return bytes;
}

template <typename Part>
bool Loads(Part& part, const std::vector<std::uint8_t>& bytes) {
  SnapshotReader r(bytes);
  part.Load(r);
  return !r.failed() && r.remaining() == 0;
}

TEST(SnapshotParts, TheCoverCellFollowsFromItsCoarseningsAndIsBoundedByTheConfig) {
  CloudCoverPolicy coarse, fresh, other;
  coarse.Init(16, 4, 0.5, 8.0);
  ASSERT_TRUE(coarse.Coarsen());
  ASSERT_TRUE(coarse.Coarsen());  // 2 m
  const std::vector<std::uint8_t> bytes = Saved(coarse);
  fresh.Init(16, 4, 0.5, 8.0);
  ASSERT_TRUE(Loads(fresh, bytes));
  EXPECT_EQ(fresh.cell_m(), 2.0);
  EXPECT_EQ(fresh.coarsenings(), 2u);
  // Into a policy that had coarsened further: the same 2 m, from the config's first cell.
  other.Init(16, 4, 0.5, 8.0);
  for (int i = 0; i < 4; ++i) ASSERT_TRUE(other.Coarsen());
  ASSERT_TRUE(Loads(other, bytes));
  EXPECT_EQ(other.cell_m(), 2.0);
  // More coarsenings than the config's largest cell allows: refused.
  std::vector<std::uint8_t> bad = bytes;
  const std::uint64_t many = 5;  // 0.5 m x 32 > 8 m
  std::memcpy(bad.data(), &many, 8);
  CloudCoverPolicy refused;
  refused.Init(16, 4, 0.5, 8.0);
  EXPECT_FALSE(Loads(refused, bad));
  EXPECT_EQ(refused.cell_m(), 0.5);
}

FreeSpaceGridConfig SmallGrid() {
  FreeSpaceGridConfig c;
  c.width = c.height = 64;
  c.origin_m = Eigen::Vector2f(-3.2f, -3.2f);
  return c;
}

TEST(SnapshotParts, TheGridsOriginFollowsFromTheCellsItMoved) {
  FreeSpaceGrid moved, fresh;
  ASSERT_TRUE(moved.Init(SmallGrid()));
  ASSERT_TRUE(moved.Follow(Eigen::Vector2f(7.3f, -4.1f)));
  ASSERT_TRUE(moved.Follow(Eigen::Vector2f(15.0f, 2.0f)));
  const std::vector<std::uint8_t> bytes = Saved(moved);
  ASSERT_TRUE(fresh.Init(SmallGrid()));
  ASSERT_TRUE(Loads(fresh, bytes));
  EXPECT_EQ(fresh.origin_m(), moved.origin_m());  // bit for bit
  EXPECT_EQ(fresh.moves(), moved.moves());
  // Moved cells out of any mission's reach (INT_MIN among them): refused, origin as configured.
  for (int v : {INT_MIN, INT_MAX, -(1 << 25)}) {
    std::vector<std::uint8_t> bad = bytes;
    std::memcpy(bad.data() + bad.size() - 8, &v, 4);  // the moved cells are written last
    FreeSpaceGrid refused;
    ASSERT_TRUE(refused.Init(SmallGrid()));
    EXPECT_FALSE(Loads(refused, bad)) << v;
    EXPECT_EQ(refused.origin_m(), SmallGrid().origin_m) << v;
  }
}

TEST(SnapshotParts, ACloudStoreWhoseOrderDoesNotHoldTogetherIsRefused) {
  KeyframeCloudStore store;
  store.Init(8, 1000);
  const std::vector<Eigen::Vector3f> cloud(100, Eigen::Vector3f(1, 2, 3));
  for (std::uint32_t k = 0; k < 4; ++k) ASSERT_TRUE(store.Put(k, 10 + k, cloud));
  const std::vector<std::uint8_t> bytes = Saved(store);
  KeyframeCloudStore fresh;
  fresh.Init(8, 1000);
  ASSERT_TRUE(Loads(fresh, bytes));
  for (std::uint32_t k = 0; k < 4; ++k) EXPECT_EQ(fresh.Get(k, 10 + k).size(), 100u);
  // The tail: order entries (key u32, stamp u64) x 4, then the store's count of Puts, used,
  // peak and live (u64 each) and its statistics (6 x u64).
  constexpr std::size_t kTail = 4 * 8 + 6 * 8, kOrder = 12;
  const std::size_t last = bytes.size() - kTail - kOrder, before = last - kOrder;
  // The last order entry a copy of the one before: one cloud listed twice (compaction would
  // slide it twice, past the store).
  std::vector<std::uint8_t> twice = bytes;
  std::memcpy(twice.data() + last, twice.data() + before, kOrder);
  // The store's count of Puts below its newest entry's stamp: the next Put would reuse it.
  std::vector<std::uint8_t> behind = bytes;
  const std::uint64_t count = 2;
  std::memcpy(behind.data() + bytes.size() - kTail, &count, 8);
  for (const auto* bad : {&twice, &behind}) {
    KeyframeCloudStore refused;
    refused.Init(8, 1000);
    EXPECT_FALSE(Loads(refused, *bad));
  }
}

}  // namespace
}  // namespace msgraphs::core
