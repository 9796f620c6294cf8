// SPDX-License-Identifier: MIT
#include "msgraphs/base/node_key.hpp"

#include <gtest/gtest.h>

#include <unordered_set>

namespace msgraphs {
namespace {

TEST(NodeKey, PackRoundTrip) {
  const NodeKey key{RobotId{7}, NodeKind::kRoom, 0xDEADBEEF};
  NodeKey back;
  ASSERT_TRUE(NodeKey::FromPacked(key.Packed(), &back));
  EXPECT_EQ(back, key);
  EXPECT_EQ(key.Packed(), (std::uint64_t{7} << 40) | (std::uint64_t{3} << 32) | 0xDEADBEEFu);
}

TEST(NodeKey, RejectsImpossibleBits) {
  NodeKey out{RobotId{1}, NodeKind::kWall, 5};
  EXPECT_FALSE(NodeKey::FromPacked(std::uint64_t{1} << 60, &out));
  EXPECT_FALSE(NodeKey::FromPacked(std::uint64_t{9} << 32, &out));  // kind 9 does not exist
  EXPECT_EQ(out, (NodeKey{RobotId{1}, NodeKind::kWall, 5}));      // untouched
}

TEST(NodeKey, SameIndexOnDifferentRobotsOrLayersIsDifferent) {
  std::unordered_set<NodeKey> keys;
  keys.insert({RobotId{1}, NodeKind::kKeyframe, 3});
  keys.insert({RobotId{2}, NodeKind::kKeyframe, 3});
  keys.insert({RobotId{1}, NodeKind::kWall, 3});
  keys.insert({RobotId{1}, NodeKind::kKeyframe, 3});
  EXPECT_EQ(keys.size(), 3u);
  EXPECT_LT((NodeKey{RobotId{1}, NodeKind::kKeyframe, 9}), (NodeKey{RobotId{2}, NodeKind::kOrigin, 0}));
  EXPECT_FALSE(RobotId{}.valid());
}

}  // namespace
}  // namespace msgraphs
