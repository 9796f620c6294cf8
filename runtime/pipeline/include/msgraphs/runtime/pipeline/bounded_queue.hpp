// SPDX-License-Identifier: MIT
// BoundedQueue<T>: the fixed-capacity queue between two of the node's threads (one producer,
// one consumer). Its `capacity` slots are constructed once; elements are filled and read in
// place, so a slot's buffers (a scan's points) are reused and nothing allocates after
// construction.
//
// When full, the producer either waits (recorded inputs in lock-step: nothing may be lost) or
// gets nullptr at once and the loss is counted in dropped() (live sensors: the newest is
// refused, so what is queued stays in order). peak() is the high-water mark.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <mutex>
#include <vector>

#include "msgraphs/base/time.hpp"

namespace msgraphs::runtime {

struct QueueStats {
  std::size_t size = 0, peak = 0, capacity = 0;
  std::uint64_t pushed = 0, dropped = 0;
};

template <typename T>
class BoundedQueue {
 public:
  explicit BoundedQueue(std::size_t capacity) : slots_(capacity) {}

  std::size_t capacity() const { return slots_.size(); }

  /// A free slot to fill, or nullptr when the queue stays full for `wait` (counted as a drop
  /// when `count_drop`) or is closed. Call CommitPush() once it is filled.
  T* BeginPush(Duration wait, bool count_drop = true) {
    std::unique_lock<std::mutex> lock(mutex_);
    if (size_ == slots_.size() && wait > Duration()) {
      not_full_.wait_for(lock, std::chrono::nanoseconds(wait.nanoseconds()),
                         [&] { return size_ < slots_.size() || closed_; });
    }
    if (closed_) return nullptr;
    if (size_ == slots_.size()) {
      if (count_drop) ++dropped_;
      return nullptr;
    }
    return &slots_[(head_ + size_) % slots_.size()];
  }
  void CommitPush() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      ++size_;
      if (size_ > peak_) peak_ = size_;
      ++pushed_;
    }
    not_empty_.notify_one();
  }

  /// The oldest element, waiting up to `wait` for one; nullptr when none. It stays queued
  /// (and its slot untouched) until Pop().
  T* Front(Duration wait) {
    std::unique_lock<std::mutex> lock(mutex_);
    if (size_ == 0 && wait > Duration()) {
      not_empty_.wait_for(lock, std::chrono::nanoseconds(wait.nanoseconds()),
                          [&] { return size_ > 0 || closed_; });
    }
    return size_ == 0 ? nullptr : &slots_[head_];
  }
  void Pop() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (size_ == 0) return;
      head_ = (head_ + 1) % slots_.size();
      --size_;
    }
    not_full_.notify_one();
  }

  /// The producer has finished (end of a recording, or shutdown): wakes both sides.
  void Close() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      closed_ = true;
    }
    not_full_.notify_all();
    not_empty_.notify_all();
  }
  bool closed() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return closed_;
  }

  QueueStats stats() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return {size_, peak_, slots_.size(), pushed_, dropped_};
  }

 private:
  mutable std::mutex mutex_;
  std::condition_variable not_full_, not_empty_;
  std::vector<T> slots_;
  std::size_t head_ = 0, size_ = 0, peak_ = 0;
  std::uint64_t pushed_ = 0, dropped_ = 0;
  bool closed_ = false;
};

}  // namespace msgraphs::runtime
