// SPDX-License-Identifier: MIT
// The node's hand-over of the own map from the SLAM thread to the collab thread: the producer
// never waits for the consumer's work, never overwrites what the consumer has not taken, and
// never writes the slot the consumer holds.
#include <gtest/gtest.h>

#include <atomic>
#include <future>
#include <thread>

#include "alloc_counter.hpp"
#include "msgraphs/runtime/pipeline/handover.hpp"

namespace msgraphs::runtime {
namespace {

TEST(Handover, APostedSlotIsNeverOverwrittenAndATakenOneNeverHandedOut) {
  Handover<int> h;
  int* a = h.Begin();
  ASSERT_NE(a, nullptr);
  *a = 1;
  h.Post(a);
  EXPECT_EQ(h.Begin(), nullptr) << "posted, not taken: the producer must try again later";
  int* taken = h.Take();
  ASSERT_EQ(taken, a);
  EXPECT_EQ(*taken, 1);
  EXPECT_EQ(h.Take(), nullptr) << "nothing new posted";
  int* b = h.Begin();
  ASSERT_NE(b, nullptr);
  EXPECT_NE(b, taken) << "the consumer still works on the taken slot";
  *b = 2;
  h.Post(b);
  EXPECT_EQ(h.Begin(), nullptr);
  h.Release();
  EXPECT_EQ(h.Take(), b);
  int* c = h.Begin();
  EXPECT_EQ(c, a) << "the released slot is free again";
}

// The consumer takes a slot and then blocks (as the collab thread in a long Match) until the
// producer has filled and posted the other slot and found the next Begin deferred: were any
// call to wait for the consumer, this test would never finish.
TEST(Handover, TheProducerGoesOnWhileTheConsumerHoldsItsSlot) {
  Handover<int> h;
  int* first = h.Begin();
  *first = 1;
  h.Post(first);
  std::promise<void> producer_done;
  std::atomic<int*> held{nullptr};
  std::promise<void> taken;
  std::thread consumer([&] {
    held = h.Take();
    taken.set_value();
    producer_done.get_future().wait();  // busy "in Match" until the producer went on
    h.Release();
  });
  taken.get_future().wait();
  ASSERT_EQ(held.load(), first);
  int* second = h.Begin();
  ASSERT_NE(second, nullptr);
  ASSERT_NE(second, first);
  *second = 2;
  h.Post(second);
  EXPECT_EQ(h.Begin(), nullptr) << "deferred, not blocked";
  producer_done.set_value();
  consumer.join();
  EXPECT_EQ(*h.Take(), 2);
}

TEST(Handover, PassingSlotsAllocatesNothing) {
  Handover<int> h;
  test::AllocationScope scope;
  for (int i = 0; i < 100; ++i) {
    int* s = h.Begin();
    ASSERT_NE(s, nullptr);
    *s = i;
    h.Post(s);
    int* t = h.Take();
    ASSERT_EQ(*t, i);
    h.Release();
  }
  EXPECT_EQ(scope.allocations(), 0u);
}

}  // namespace
}  // namespace msgraphs::runtime
