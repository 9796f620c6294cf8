// SPDX-License-Identifier: MIT
// Handover<T>: two slots passed from one producer thread to one consumer thread without either
// waiting for the other's work. The producer fills a slot that is neither posted nor taken and
// posts it; the consumer takes the posted slot, works on it as long as it likes, and releases
// it. The lock is held for a pointer's assignment only, never across either side's work.
//
// The node hands the own map (CollabExchange) from the SLAM thread to the collab thread with
// it: while the collab thread works on the slot it took (sending it), the SLAM thread's next
// exchange goes into the other one; while a posted slot waits (the collab thread busy in a
// Match of seconds), Begin returns nullptr at once: the producer does not overwrite what the
// consumer has not seen, and tries again later (the node after its next scan). Neither ever
// waits for the other's work. The slots are the caller's to size (slots()), before the threads
// start; nothing here allocates.
#pragma once

#include <array>
#include <mutex>

namespace msgraphs::runtime {

template <typename T>
class Handover {
 public:
  /// Both slots, to size before the threads start.
  std::array<T, 2>& slots() { return slots_; }

  /// Producer: a slot to fill (neither posted nor taken), or nullptr while the last one posted
  /// has not been taken. Never blocks on the consumer's work.
  T* Begin() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (posted_ != nullptr) return nullptr;
    return taken_ == &slots_[0] ? &slots_[1] : &slots_[0];
  }
  /// Producer: `slot` (from Begin) is filled.
  void Post(T* slot) {
    std::lock_guard<std::mutex> lock(mutex_);
    posted_ = slot;
  }
  /// Consumer: the posted slot, now taken (the producer leaves it alone), or nullptr.
  T* Take() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (posted_ == nullptr) return nullptr;
    taken_ = posted_;
    posted_ = nullptr;
    return taken_;
  }
  /// Consumer: done with the taken slot.
  void Release() {
    std::lock_guard<std::mutex> lock(mutex_);
    taken_ = nullptr;
  }

 private:
  std::mutex mutex_;
  std::array<T, 2> slots_;
  T* posted_ = nullptr;
  T* taken_ = nullptr;
};

}  // namespace msgraphs::runtime
