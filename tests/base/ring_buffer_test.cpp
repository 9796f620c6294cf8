// SPDX-License-Identifier: MIT
#include "msgraphs/base/ring_buffer.hpp"

#include <gtest/gtest.h>

namespace msgraphs {
namespace {

TEST(RingBuffer, FifoOrderAcrossWrap) {
  RingBuffer<int, 3> rb;
  for (int round = 0; round < 5; ++round) {
    EXPECT_EQ(rb.push(round * 10), PushResult::kOk);
    EXPECT_EQ(rb.push(round * 10 + 1), PushResult::kOk);
    EXPECT_EQ(rb.pop(), round * 10);
    EXPECT_EQ(rb.pop(), round * 10 + 1);
  }
  EXPECT_FALSE(rb.pop().has_value());
  EXPECT_EQ(rb.dropped(), 0u);
  EXPECT_EQ(rb.peak(), 2u);
}

TEST(RingBuffer, RejectNewestKeepsQueuedElements) {
  RingBuffer<int, 2> rb(OverflowPolicy::kRejectNewest);
  static_cast<void>(rb.push(1));
  static_cast<void>(rb.push(2));
  EXPECT_EQ(rb.push(3), PushResult::kRejected);
  EXPECT_EQ(rb.dropped(), 1u);
  EXPECT_EQ(rb.pop(), 1);
  EXPECT_EQ(rb.pop(), 2);
}

TEST(RingBuffer, DropOldestKeepsFreshestElements) {
  RingBuffer<int, 2> rb(OverflowPolicy::kDropOldest);
  static_cast<void>(rb.push(1));
  static_cast<void>(rb.push(2));
  EXPECT_EQ(rb.push(3), PushResult::kDroppedOldest);
  EXPECT_EQ(rb.push(4), PushResult::kDroppedOldest);
  EXPECT_EQ(rb.dropped(), 2u);
  EXPECT_EQ(rb.front(), 3);
  EXPECT_EQ(rb.pop(), 3);
  EXPECT_EQ(rb.pop(), 4);
  EXPECT_EQ(rb.peak(), 2u);
}

}  // namespace
}  // namespace msgraphs
