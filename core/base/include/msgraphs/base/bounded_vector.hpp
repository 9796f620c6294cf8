// SPDX-License-Identifier: MIT
// BoundedVector<T>: a vector whose capacity is chosen at run time, once. Init() allocates the
// whole capacity; nothing after it does. For buffers sized by configuration (points per scan,
// keyframes per graph) where FixedVector's compile-time capacity does not fit.
//
// Full: try_push_back returns false and counts the rejection (rejected()); push_back treats it
// as a contract violation. peak() reports the high-water mark since Init or ResetPeak.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <type_traits>

#include "msgraphs/base/assert.hpp"

namespace msgraphs {

template <typename T>
class BoundedVector {
  // Elements are default-constructed at Init and assigned later, which keeps the class simple
  // and safe; restricting T to cheap, copyable types keeps that honest.
  static_assert(std::is_default_constructible_v<T> && std::is_copy_assignable_v<T>);

 public:
  BoundedVector() = default;
  explicit BoundedVector(std::size_t capacity) { Init(capacity); }

  /// Allocates `capacity` elements (the only allocation) and empties the vector.
  void Init(std::size_t capacity) {
    data_ = std::make_unique<T[]>(capacity);
    capacity_ = capacity;
    size_ = peak_ = 0;
    rejected_ = 0;
  }

  std::size_t capacity() const noexcept { return capacity_; }
  std::size_t size() const noexcept { return size_; }
  bool empty() const noexcept { return size_ == 0; }
  bool full() const noexcept { return size_ == capacity_; }
  std::size_t peak() const noexcept { return peak_; }
  std::uint64_t rejected() const noexcept { return rejected_; }
  void ResetPeak() noexcept { peak_ = size_; }

  [[nodiscard]] bool try_push_back(const T& value) noexcept(std::is_nothrow_copy_assignable_v<T>) {
    if (full()) {
      ++rejected_;
      return false;
    }
    data_[size_++] = value;
    if (size_ > peak_) peak_ = size_;
    return true;
  }
  void push_back(const T& value) {
    MSGRAPHS_ASSERT(!full(), "BoundedVector capacity exceeded");
    static_cast<void>(try_push_back(value));
  }
  /// Shrinks to `n` elements (n <= size()). Elements past n keep their values but are dead.
  void resize_down(std::size_t n) {
    MSGRAPHS_ASSERT(n <= size_, "BoundedVector::resize_down cannot grow");
    size_ = n;
  }
  void clear() noexcept { size_ = 0; }

  T& operator[](std::size_t i) {
    MSGRAPHS_DEBUG_ASSERT(i < size_, "BoundedVector index out of range");
    return data_[i];
  }
  const T& operator[](std::size_t i) const {
    MSGRAPHS_DEBUG_ASSERT(i < size_, "BoundedVector index out of range");
    return data_[i];
  }
  T* data() noexcept { return data_.get(); }
  const T* data() const noexcept { return data_.get(); }
  T* begin() noexcept { return data(); }
  T* end() noexcept { return data() + size_; }
  const T* begin() const noexcept { return data(); }
  const T* end() const noexcept { return data() + size_; }
  std::span<T> span() noexcept { return {data(), size_}; }
  std::span<const T> span() const noexcept { return {data(), size_}; }

 private:
  std::unique_ptr<T[]> data_;
  std::size_t capacity_ = 0;
  std::size_t size_ = 0;
  std::size_t peak_ = 0;
  std::uint64_t rejected_ = 0;
};

}  // namespace msgraphs
