// SPDX-License-Identifier: MIT
// Test-only allocation counting. alloc_counter.cpp replaces the global operator new/delete (all
// overloads) in test executables only: it is an OBJECT library linked into tests, never into
// msgraphs_node or the libraries.
//
//   msgraphs::test::AllocationScope scope;      // counts this thread's allocations from here
//   ... the steady-state path ...
//   EXPECT_EQ(scope.allocations(), 0u);
#pragma once

#include <cstddef>
#include <cstdint>

namespace msgraphs::test {

/// Allocations (operator new calls, any overload) made by the calling thread so far.
std::uint64_t ThreadAllocationCount() noexcept;
/// Bytes requested by those allocations.
std::uint64_t ThreadAllocatedBytes() noexcept;
/// Allocations made by all threads so far.
std::uint64_t GlobalAllocationCount() noexcept;

/// Counts the calling thread's allocations between construction and the call.
class AllocationScope {
 public:
  AllocationScope() noexcept
      : start_count_(ThreadAllocationCount()), start_bytes_(ThreadAllocatedBytes()) {}
  std::uint64_t allocations() const noexcept { return ThreadAllocationCount() - start_count_; }
  std::uint64_t bytes() const noexcept { return ThreadAllocatedBytes() - start_bytes_; }

 private:
  std::uint64_t start_count_;
  std::uint64_t start_bytes_;
};

/// Keeps the optimiser from removing a value or an allocation whose result is never read
/// (C++ allows eliding a new/delete pair).
template <typename T>
inline void DoNotOptimize(T const& value) {
  asm volatile("" : : "r,m"(value) : "memory");
}

}  // namespace msgraphs::test
