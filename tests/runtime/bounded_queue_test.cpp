// SPDX-License-Identifier: MIT
#include "msgraphs/runtime/pipeline/bounded_queue.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <thread>
#include <vector>

#include "alloc_counter.hpp"
#include "msgraphs/runtime/pipeline/replay_clock.hpp"

namespace msgraphs::runtime {
namespace {

TEST(BoundedQueue, FifoInPlaceWithPeakAndDrops) {
  BoundedQueue<std::vector<int>> q(2);
  for (int i = 0; i < 2; ++i) {
    std::vector<int>* slot = q.BeginPush(Duration());
    ASSERT_NE(slot, nullptr);
    slot->assign(3, i);
    q.CommitPush();
  }
  EXPECT_EQ(q.BeginPush(Duration()), nullptr);         // full: refused, counted
  EXPECT_EQ(q.BeginPush(Duration(), false), nullptr);  // a waiting producer's retry: not counted
  ASSERT_NE(q.Front(Duration()), nullptr);
  EXPECT_EQ(q.Front(Duration())->front(), 0);
  q.Pop();
  EXPECT_EQ(q.Front(Duration())->front(), 1);
  const QueueStats s = q.stats();
  EXPECT_EQ(s.peak, 2u);
  EXPECT_EQ(s.dropped, 1u);
  EXPECT_EQ(s.pushed, 2u);
  EXPECT_EQ(s.size, 1u);
}

TEST(BoundedQueue, ReusesSlotBuffers) {
  BoundedQueue<std::vector<int>> q(1);
  std::vector<int>* slot = q.BeginPush(Duration());
  slot->reserve(100);
  const int* storage = slot->data();
  q.CommitPush();
  q.Pop();
  slot = q.BeginPush(Duration());
  slot->assign(50, 7);
  EXPECT_EQ(slot->data(), storage);  // same slot, same buffer: no allocation in steady state
}

TEST(BoundedQueue, LockstepProducerWaitsAndLosesNothing) {
  BoundedQueue<int> q(3);
  constexpr int kItems = 10000;
  std::thread producer([&] {
    for (int i = 0; i < kItems; ++i) {
      int* slot = nullptr;
      while ((slot = q.BeginPush(Duration::FromMilliseconds(10), false)) == nullptr) {
      }
      *slot = i;
      q.CommitPush();
    }
    q.Close();
  });
  int expected = 0;
  for (;;) {
    int* item = q.Front(Duration::FromMilliseconds(10));
    if (item == nullptr) {
      if (q.closed() && q.Front(Duration()) == nullptr) break;
      continue;
    }
    ASSERT_EQ(*item, expected++);
    q.Pop();
  }
  producer.join();
  EXPECT_EQ(expected, kItems);
  EXPECT_EQ(q.stats().dropped, 0u);
  EXPECT_LE(q.stats().peak, 3u);
}

TEST(BoundedQueue, CloseWakesAWaitingProducer) {
  BoundedQueue<int> q(1);
  *q.BeginPush(Duration()) = 1;
  q.CommitPush();
  std::thread closer([&] { q.Close(); });
  EXPECT_EQ(q.BeginPush(Duration::FromSeconds(5)), nullptr);
  closer.join();
}

// bounded_queue.hpp: "nothing allocates after construction". The queue is constructed and each
// slot's buffer sized once (the first fill); then 1000 cycles fill it, are refused (full: a
// drop), and drain it in order, refilling the slots in place.
TEST(BoundedQueue, NothingAllocatesAfterConstruction) {
  constexpr std::size_t kSlots = 4;
  constexpr int kCycles = 1000;
  BoundedQueue<std::vector<int>> q(kSlots);
  for (std::size_t i = 0; i < kSlots; ++i) {
    std::vector<int>* slot = q.BeginPush(Duration());
    ASSERT_NE(slot, nullptr);
    slot->reserve(256);
    q.CommitPush();
  }
  for (std::size_t i = 0; i < kSlots; ++i) q.Pop();

  int refused = 0, out_of_order = 0, popped = 0, expected = 0, next = 0;
  test::AllocationScope scope;
  for (int cycle = 0; cycle < kCycles; ++cycle) {
    for (std::size_t i = 0; i < kSlots; ++i) {
      std::vector<int>* slot = q.BeginPush(Duration());
      if (slot == nullptr) break;
      slot->assign(100 + static_cast<std::size_t>(cycle % 100), next++);
      q.CommitPush();
    }
    if (q.BeginPush(Duration()) == nullptr) ++refused;  // full: refused and counted
    for (std::vector<int>* item = q.Front(Duration()); item != nullptr; item = q.Front(Duration())) {
      if (item->empty() || item->front() != expected || item->size() != 100 + static_cast<std::size_t>(cycle % 100))
        ++out_of_order;
      ++expected;
      ++popped;
      q.Pop();
    }
  }
  const std::uint64_t allocations = scope.allocations();

  EXPECT_EQ(allocations, 0u);
  EXPECT_EQ(refused, kCycles);
  EXPECT_EQ(out_of_order, 0);
  EXPECT_EQ(popped, kCycles * static_cast<int>(kSlots));
  const QueueStats s = q.stats();
  EXPECT_EQ(s.dropped, static_cast<std::uint64_t>(kCycles));
  EXPECT_EQ(s.pushed, kSlots + static_cast<std::uint64_t>(kCycles) * kSlots);
  EXPECT_EQ(s.peak, kSlots);
  EXPECT_EQ(s.size, 0u);
}

TEST(ReplayClock, KeepsTwoInputsInStepAtTheGivenSpeed) {
  ReplayClock clock(2.0);
  const SteadyTime t0 = SteadyTime::FromSeconds(100);
  EXPECT_EQ(clock.Due(1000.0, t0).seconds_since_epoch(), 100.0);
  EXPECT_DOUBLE_EQ(clock.Due(1010.0, t0).seconds_since_epoch(), 105.0);  // 10 s at 2x
  // An earlier stamp from the other input moves the anchor back: both stay in step.
  EXPECT_DOUBLE_EQ(clock.Due(999.0, t0).seconds_since_epoch(), 99.5);
  EXPECT_DOUBLE_EQ(clock.Due(1010.0, t0).seconds_since_epoch(), 105.0);
}

}  // namespace
}  // namespace msgraphs::runtime
