// SPDX-License-Identifier: MIT
// The keyframe cloud store: every cloud read back is the one put under that key and sequence,
// through any order of sizes and reused keys; a full store evicts what its retention policy
// allows (covered clouds first, never pinned ones, places made coarser before a unique cloud
// goes); the mapper's policy tells its kinds of cloud apart; nothing allocates after Init.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <set>
#include <vector>

#include "alloc_counter.hpp"
#include "msgraphs/core/graph/s_graph.hpp"
#include "msgraphs/core/slam/cloud_cover_policy.hpp"
#include "msgraphs/core/slam/keyframe_cloud_store.hpp"

namespace msgraphs::core {
namespace {

// Points that say whose they are: x = key, y = sequence, z = index in the cloud.
std::vector<Eigen::Vector3f> Labelled(std::uint32_t key, std::uint64_t sequence, std::size_t n) {
  std::vector<Eigen::Vector3f> cloud(n);
  for (std::size_t i = 0; i < n; ++i)
    cloud[i] = Eigen::Vector3f(static_cast<float>(key), static_cast<float>(sequence), static_cast<float>(i));
  return cloud;
}

bool IsOwn(std::span<const Eigen::Vector3f> cloud, std::uint32_t key, std::uint64_t sequence, std::size_t n) {
  if (cloud.size() != n) return false;
  for (std::size_t i = 0; i < n; ++i) {
    if (cloud[i] != Eigen::Vector3f(static_cast<float>(key), static_cast<float>(sequence), static_cast<float>(i)))
      return false;
  }
  return true;
}

TEST(KeyframeCloudStore, EvictsTheOldestAndTellsReusedKeysApart) {
  KeyframeCloudStore s;
  s.Init(4, 100);
  const std::vector<Eigen::Vector3f> forty(40, Eigen::Vector3f(1, 2, 3));
  ASSERT_TRUE(s.Put(0, 1, forty));
  ASSERT_TRUE(s.Put(1, 2, forty));
  EXPECT_EQ(s.Get(0, 1).size(), 40u);
  EXPECT_TRUE(s.Get(0, 7).empty());  // another owner of key 0
  ASSERT_TRUE(s.Put(2, 3, forty));   // full: evicts key 0 only
  EXPECT_TRUE(s.Get(0, 1).empty());
  EXPECT_EQ(s.Get(1, 2).size(), 40u);
  EXPECT_EQ(s.Get(2, 3).size(), 40u);
  EXPECT_EQ(s.evicted(), 1u);
  EXPECT_LE(s.used_points(), 100u);
  EXPECT_EQ(s.peak_points(), 80u);
  const std::vector<Eigen::Vector3f> huge(101, Eigen::Vector3f::Zero());
  EXPECT_EQ(s.Put(3, 4, huge).error().code, Errc::kCapacityExceeded);
  EXPECT_EQ(s.Put(9, 4, forty).error().code, Errc::kInvalidArgument);
}

// The ring this store replaced wrapped to its start when a cloud did not fit before its end and
// evicted only the clouds in the way from the oldest on: once the store had gone round twice,
// the oldest lay in the abandoned tail, nothing was evicted and the newer cloud at the start was
// overwritten while still listed (this exact sequence). Then thousands of random puts.
TEST(KeyframeCloudStore, EveryCloudReadBackIsTheOnePut) {
  KeyframeCloudStore s;
  s.Init(8, 10);
  const std::pair<std::uint32_t, std::size_t> puts[] = {{0, 6}, {1, 2}, {2, 2}, {3, 6}, {4, 5}};
  std::uint64_t sequence = 0;
  for (const auto& [key, n] : puts) {
    ++sequence;
    ASSERT_TRUE(s.Put(key, sequence, Labelled(key, sequence, n)));
  }
  EXPECT_TRUE(IsOwn(s.Get(4, 5), 4, 5, 5));
  const auto r = s.Get(3, 4);
  EXPECT_TRUE(r.empty() || IsOwn(r, 3, 4, 6)) << "key 3 lists points that are not its own";

  std::mt19937 rng(7);
  KeyframeCloudStore big;
  big.Init(64, 5000, 700);
  std::vector<std::uint64_t> owner(64, 0);
  std::vector<std::size_t> size(64, 0);
  std::size_t found = 0;
  for (std::uint64_t seq = 1; seq <= 5000; ++seq) {
    const auto key = static_cast<std::uint32_t>(rng() % 64);
    const std::size_t n = 1 + rng() % 900;
    ASSERT_TRUE(big.Put(key, seq, Labelled(key, seq, n)));
    owner[key] = seq;
    size[key] = n;
    std::size_t used = 0;
    for (std::uint32_t k = 0; k < 64; ++k) {
      const auto cloud = big.Get(k, owner[k]);
      if (cloud.empty()) continue;
      ASSERT_TRUE(IsOwn(cloud, k, owner[k], size[k])) << "put " << seq << ", key " << k;
      used += cloud.size();
      ++found;
    }
    ASSERT_EQ(used, big.used_points());
    ASSERT_LE(used, 5000u);
    ASSERT_TRUE(IsOwn(big.Get(key, seq), key, seq, n));  // the newest is always there
  }
  EXPECT_GT(big.evicted(), 1000u);
  EXPECT_GT(found, 5u * 5000u);  // about 11 clouds of 450 points fit: at least 5 stored on average
}

// Places by key / 4 (four keys share a place), keys in `pinned` never go; Coarsen makes places
// of key / 16 once. Key k's cloud is looked up with sequence k + 1, or `sequences[k]`.
class PlacePolicy final : public CloudRetentionPolicy {
 public:
  PlacePolicy(const KeyframeCloudStore& store, std::set<std::uint32_t> pinned,
              const std::vector<std::uint64_t>* sequences = nullptr)
      : store_(store), pinned_(std::move(pinned)), sequences_(sequences) {}
  void BeginPass() override { ++passes; }
  CloudRetention Retention(std::uint32_t key, std::uint64_t) const override {
    if (pinned_.count(key) != 0) return CloudRetention::kPinned;
    const std::uint32_t place = key / group;
    for (std::uint32_t other = place * group; other < (place + 1) * group; ++other) {
      const std::uint64_t sequence = sequences_ != nullptr ? (*sequences_)[other] : other + 1;
      if (other != key && !store_.Get(other, sequence).empty()) return CloudRetention::kReplaceable;
    }
    return CloudRetention::kUnique;
  }
  bool Coarsen() override {
    if (group == 16) return false;
    group = 16;
    ++coarsened;
    return true;
  }
  std::uint32_t group = 4;
  int passes = 0, coarsened = 0;

 private:
  const KeyframeCloudStore& store_;
  std::set<std::uint32_t> pinned_;
  const std::vector<std::uint64_t>* sequences_;
};

TEST(KeyframeCloudStore, AFullStoreEvictsWhatItsPolicyAllows) {
  KeyframeCloudStore s;
  s.Init(64, 1000);  // ten clouds of 100
  PlacePolicy policy(s, {8});
  const auto put = [&](KeyframeCloudStore& store, PlacePolicy& p, std::uint32_t key) {
    return store.Put(key, key + 1, Labelled(key, key + 1, 100), &p);
  };
  const auto has = [](const KeyframeCloudStore& store, std::uint32_t key) { return !store.Get(key, key + 1).empty(); };
  for (std::uint32_t key = 0; key < 10; ++key) ASSERT_TRUE(put(s, policy, key));
  // Full. Places of four: the oldest of a place go while it has company; 3 and 7 stay alone;
  // pinned 8 never goes but covers 9..11.
  for (std::uint32_t key = 10; key < 20; ++key) ASSERT_TRUE(put(s, policy, key));
  for (std::uint32_t key : {0u, 1u, 2u, 4u, 5u, 6u, 9u, 10u, 11u, 12u}) EXPECT_FALSE(has(s, key)) << key;
  for (std::uint32_t key : {3u, 7u, 8u, 13u, 14u, 15u, 16u, 17u, 18u, 19u}) EXPECT_TRUE(has(s, key)) << key;
  EXPECT_EQ(s.stats().evicted_covered, 10u);
  EXPECT_EQ(s.stats().evicted_uncovered, 0u);
  EXPECT_EQ(policy.coarsened, 0);
  for (std::uint32_t key = 3; key < 20; ++key) {
    if (has(s, key)) {
      EXPECT_TRUE(IsOwn(s.Get(key, key + 1), key, key + 1, 100));
    }
  }

  // Four unique places, full: places are made coarser before a unique cloud goes.
  KeyframeCloudStore t;
  t.Init(64, 400);
  PlacePolicy coarse(t, {});
  for (std::uint32_t key : {0u, 4u, 8u, 12u}) ASSERT_TRUE(put(t, coarse, key));
  ASSERT_TRUE(put(t, coarse, 16));  // places of sixteen: 0 is covered by 4, 8, 12
  EXPECT_EQ(coarse.coarsened, 1);
  EXPECT_FALSE(has(t, 0));
  ASSERT_TRUE(put(t, coarse, 32));  // 4 goes (8, 12)
  ASSERT_TRUE(put(t, coarse, 48));  // 8 goes (12)
  EXPECT_EQ(t.stats().evicted_covered, 3u);
  EXPECT_EQ(t.stats().evicted_uncovered, 0u);
  // 12, 16, 32, 48 each alone in its place of sixteen, none coarser: the oldest unique goes.
  ASSERT_TRUE(put(t, coarse, 60));
  EXPECT_FALSE(has(t, 12));
  EXPECT_EQ(t.stats().evicted_uncovered, 1u);
  for (std::uint32_t key : {16u, 32u, 48u, 60u}) EXPECT_TRUE(has(t, key)) << key;

  // Only pinned clouds: a cloud that cannot fit is refused and nothing pinned goes.
  PlacePolicy all_pinned(t, {16, 32, 48, 60});
  EXPECT_EQ(t.Put(1, 2, Labelled(1, 2, 100), &all_pinned).error().code, Errc::kCapacityExceeded);
  EXPECT_EQ(t.stats().refused, 1u);
  for (std::uint32_t key : {16u, 32u, 48u, 60u}) EXPECT_TRUE(has(t, key)) << key;
}

// The mapper's policy on a graph of eight keyframes, places of 1 m: two sharing a cell cover
// each other; one whose cell holds only the keyframe being put, or a pinned (newest) one, is
// revisited; one alone is unique; the newest three are pinned; a stale sequence is gone.
TEST(CloudCoverPolicy, TellsGoneCoveredRevisitedUniqueAndPinnedApart) {
  SGraphConfig config;
  config.max_keyframes = 64;
  SGraph graph;
  const Status init = graph.Init(config);
  ASSERT_TRUE(init) << init.error().detail;
  const double xy[8][2] = {{0.2, 0.2}, {0.4, 0.3}, {5.2, 0.2}, {10.2, 0.2},
                           {15.2, 0.2}, {10.4, 0.5}, {20.2, 0.2}, {5.5, 0.6}};
  KeyframeCloudStore store;
  store.Init(65, 10000);
  std::vector<std::uint64_t> sequences(65, 0);
  for (std::uint32_t i = 0; i < 8; ++i) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() = Eigen::Vector3d(xy[i][0], xy[i][1], 0.5);
    const auto id = graph.AddKeyframe(static_cast<double>(i), T);
    ASSERT_TRUE(id);
    ASSERT_EQ(*id, i);
    sequences[i] = i + 1;
    if (i < 7) {
      ASSERT_TRUE(store.Put(i, i + 1, Labelled(i, i + 1, 10)));  // 7 is being put
    }
  }
  CloudCoverPolicy policy;
  policy.Init(65, 3, 1.0, 4.0);
  policy.Bind(store, graph, sequences, 7);
  policy.BeginPass();
  EXPECT_EQ(policy.Retention(0, 1), CloudRetention::kReplaceable);  // 1 is settled, same cell
  EXPECT_EQ(policy.Retention(1, 2), CloudRetention::kReplaceable);
  EXPECT_EQ(policy.Retention(2, 3), CloudRetention::kRevisited);    // only 7, being put
  EXPECT_EQ(policy.Retention(3, 4), CloudRetention::kRevisited);    // only 5, pinned
  EXPECT_EQ(policy.Retention(4, 5), CloudRetention::kUnique);
  for (std::uint32_t k : {5u, 6u}) EXPECT_EQ(policy.Retention(k, k + 1), CloudRetention::kPinned) << k;
  EXPECT_EQ(policy.Retention(0, 99), CloudRetention::kGone);  // another owner of slot 0
  // Places of 2 m, then 4 m, then no coarser: at 4 m, 2 (x 5.2) and 4 (x 15.2) stay apart
  // from the rest, 3 shares its cell with pinned 5.
  EXPECT_TRUE(policy.Coarsen());
  EXPECT_TRUE(policy.Coarsen());
  EXPECT_FALSE(policy.Coarsen());
  EXPECT_EQ(policy.cell_m(), 4.0);
  EXPECT_EQ(policy.coarsenings(), 2u);
  policy.BeginPass();
  EXPECT_EQ(policy.Retention(0, 1), CloudRetention::kReplaceable);
  EXPECT_EQ(policy.Retention(2, 3), CloudRetention::kRevisited);
  EXPECT_EQ(policy.Retention(4, 5), CloudRetention::kUnique);
}

TEST(KeyframeCloudStore, PuttingAndGettingAllocateNothingAfterInit) {
  KeyframeCloudStore s;
  s.Init(8, 1000, 300);
  const std::vector<Eigen::Vector3f> cloud(150, Eigen::Vector3f(1, 2, 3));
  std::vector<std::uint64_t> sequences(8, 0);
  PlacePolicy policy(s, {7}, &sequences);
  std::size_t found = 0;
  test::AllocationScope scope;
  // 200 keyframes through 8 keys and room for 6 clouds: keys reused, covered and unique clouds
  // evicted (places of four keys, key 7 pinned), with and without a policy.
  for (std::uint32_t k = 0; k < 200; ++k) {
    sequences[k % 8] = k + 1;
    ASSERT_TRUE(s.Put(k % 8, k + 1, cloud, k % 2 == 0 ? &policy : nullptr));
    found += s.Get(k % 8, k + 1).size();
  }
  EXPECT_EQ(scope.allocations(), 0u);
  EXPECT_EQ(found, 200u * 150u);
  EXPECT_GT(s.evicted(), 150u);
  EXPECT_GT(s.stats().evicted_covered, 0u);
  EXPECT_GT(s.stats().compactions, 0u);
}

}  // namespace
}  // namespace msgraphs::core
