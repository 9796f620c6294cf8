// SPDX-License-Identifier: MIT
// FixedVector<T, Capacity>: a vector whose storage lives inside the object. Never allocates.
//
// Full: try_push_back/try_emplace_back return false and leave the vector unchanged;
// push_back/emplace_back treat a full vector as a contract violation. Which one a caller uses
// states its overflow policy.
#pragma once

#include <cstddef>
#include <new>
#include <span>
#include <type_traits>
#include <utility>

#include "msgraphs/base/assert.hpp"

namespace msgraphs {

template <typename T, std::size_t Capacity>
class FixedVector {
  static_assert(Capacity > 0, "a zero-capacity FixedVector is useless");

 public:
  using value_type = T;
  using iterator = T*;
  using const_iterator = const T*;

  FixedVector() = default;
  FixedVector(const FixedVector& other) { CopyFrom(other); }
  FixedVector& operator=(const FixedVector& other) {
    if (this != &other) {
      clear();
      CopyFrom(other);
    }
    return *this;
  }
  ~FixedVector() { clear(); }

  static constexpr std::size_t capacity() noexcept { return Capacity; }
  std::size_t size() const noexcept { return size_; }
  bool empty() const noexcept { return size_ == 0; }
  bool full() const noexcept { return size_ == Capacity; }

  template <typename... Args>
  [[nodiscard]] bool try_emplace_back(Args&&... args) {
    if (full()) return false;
    ::new (static_cast<void*>(Slot(size_))) T(std::forward<Args>(args)...);
    ++size_;
    return true;
  }
  [[nodiscard]] bool try_push_back(const T& value) { return try_emplace_back(value); }

  template <typename... Args>
  T& emplace_back(Args&&... args) {
    MSGRAPHS_ASSERT(!full(), "FixedVector capacity exceeded");
    ::new (static_cast<void*>(Slot(size_))) T(std::forward<Args>(args)...);
    return *Slot(size_++);
  }
  void push_back(const T& value) { emplace_back(value); }

  void pop_back() {
    MSGRAPHS_ASSERT(!empty(), "FixedVector::pop_back on empty");
    std::destroy_at(Slot(--size_));
  }
  void clear() noexcept {
    while (size_ > 0) std::destroy_at(Slot(--size_));
  }

  T& operator[](std::size_t i) {
    MSGRAPHS_DEBUG_ASSERT(i < size_, "FixedVector index out of range");
    return *Slot(i);
  }
  const T& operator[](std::size_t i) const {
    MSGRAPHS_DEBUG_ASSERT(i < size_, "FixedVector index out of range");
    return *Slot(i);
  }
  T& back() { return (*this)[size_ - 1]; }
  const T& back() const { return (*this)[size_ - 1]; }

  T* data() noexcept { return Slot(0); }
  const T* data() const noexcept { return Slot(0); }
  iterator begin() noexcept { return data(); }
  iterator end() noexcept { return data() + size_; }
  const_iterator begin() const noexcept { return data(); }
  const_iterator end() const noexcept { return data() + size_; }
  std::span<T> span() noexcept { return {data(), size_}; }
  std::span<const T> span() const noexcept { return {data(), size_}; }

 private:
  T* Slot(std::size_t i) noexcept { return std::launder(reinterpret_cast<T*>(storage_) + i); }
  const T* Slot(std::size_t i) const noexcept {
    return std::launder(reinterpret_cast<const T*>(storage_) + i);
  }
  void CopyFrom(const FixedVector& other) {
    for (const T& v : other) emplace_back(v);
  }

  alignas(T) std::byte storage_[sizeof(T) * Capacity];
  std::size_t size_ = 0;
};

}  // namespace msgraphs
