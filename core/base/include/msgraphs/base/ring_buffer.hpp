// SPDX-License-Identifier: MIT
// RingBuffer<T, Capacity>: a FIFO with in-object storage and an explicit overflow policy.
// Single-threaded; the runtime's thread-safe queues build on it. Never allocates.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>

#include <type_traits>

#include "msgraphs/base/assert.hpp"

namespace msgraphs {

/// What push() does when the buffer is full. Either way the loss is counted (dropped()).
enum class OverflowPolicy : std::uint8_t {
  kRejectNewest,  ///< keep what is queued, refuse the new element (sensor queues: keep order)
  kDropOldest,    ///< evict the oldest element to make room (telemetry: freshest wins)
};

enum class PushResult : std::uint8_t { kOk, kRejected, kDroppedOldest };

template <typename T, std::size_t Capacity>
class RingBuffer {
  static_assert(std::is_default_constructible_v<T> && std::is_copy_assignable_v<T>);

 public:
  explicit RingBuffer(OverflowPolicy policy = OverflowPolicy::kRejectNewest) : policy_(policy) {}

  static constexpr std::size_t capacity() noexcept { return Capacity; }
  std::size_t size() const noexcept { return size_; }
  bool empty() const noexcept { return size_ == 0; }
  bool full() const noexcept { return size_ == Capacity; }
  /// High-water mark of size() since construction or ResetPeak().
  std::size_t peak() const noexcept { return peak_; }
  /// Elements lost to the overflow policy (rejected or evicted) since construction.
  std::uint64_t dropped() const noexcept { return dropped_; }
  OverflowPolicy policy() const noexcept { return policy_; }
  void ResetPeak() noexcept { peak_ = size_; }

  PushResult push(const T& value) {
    PushResult result = PushResult::kOk;
    if (full()) {
      ++dropped_;
      if (policy_ == OverflowPolicy::kRejectNewest) return PushResult::kRejected;
      head_ = Next(head_);  // evict the oldest
      --size_;
      result = PushResult::kDroppedOldest;
    }
    slots_[(head_ + size_) % Capacity] = value;
    ++size_;
    if (size_ > peak_) peak_ = size_;
    return result;
  }

  std::optional<T> pop() {
    if (empty()) return std::nullopt;
    std::optional<T> out(slots_[head_]);
    head_ = Next(head_);
    --size_;
    return out;
  }

  /// The oldest element; the buffer must not be empty.
  const T& front() const {
    MSGRAPHS_ASSERT(!empty(), "RingBuffer::front on empty");
    return slots_[head_];
  }
  void clear() noexcept { head_ = size_ = 0; }

 private:
  static std::size_t Next(std::size_t i) noexcept { return (i + 1) % Capacity; }

  T slots_[Capacity]{};
  std::size_t head_ = 0;
  std::size_t size_ = 0;
  std::size_t peak_ = 0;
  std::uint64_t dropped_ = 0;
  OverflowPolicy policy_;
};

}  // namespace msgraphs
