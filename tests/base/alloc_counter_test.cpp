// SPDX-License-Identifier: MIT
// Proves the allocation counter works both ways: it sees an allocation, and it stays at zero
// for a loop that does not allocate. Every zero-allocation test in the project relies on this.
#include "alloc_counter.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "msgraphs/base/bounded_vector.hpp"
#include "msgraphs/base/crc32.hpp"
#include "msgraphs/base/fixed_vector.hpp"
#include "msgraphs/base/ring_buffer.hpp"
#include "msgraphs/core/geometry/se3.hpp"

namespace msgraphs {
namespace {

using test::AllocationScope;
using test::DoNotOptimize;

TEST(AllocCounter, CatchesASingleNew) {
  AllocationScope scope;
  auto p = std::make_unique<int>(42);
  DoNotOptimize(p.get());
  EXPECT_EQ(scope.allocations(), 1u);
  EXPECT_EQ(scope.bytes(), sizeof(int));
}

TEST(AllocCounter, CatchesContainerGrowth) {
  std::vector<int> v;
  AllocationScope scope;
  for (int i = 0; i < 100; ++i) v.push_back(i);
  DoNotOptimize(v.data());
  EXPECT_GT(scope.allocations(), 0u);
}

TEST(AllocCounter, CatchesAlignedAndArrayNew) {
  struct alignas(64) Wide {
    double d[8];
  };
  AllocationScope scope;
  auto a = std::make_unique<Wide>();
  auto b = std::make_unique<char[]>(1000);
  DoNotOptimize(a.get());
  DoNotOptimize(b.get());
  EXPECT_EQ(scope.allocations(), 2u);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(a.get()) % 64, 0u);
}

TEST(AllocCounter, CountsPerThread) {
  const std::uint64_t global_before = test::GlobalAllocationCount();
  AllocationScope scope;
  std::thread other([] {
    for (int i = 0; i < 100; ++i) {
      auto p = std::make_unique<int>(i);
      DoNotOptimize(p.get());
    }
  });
  other.join();
  // This thread allocated only std::thread's state; the other thread's 100 are its own.
  EXPECT_LT(scope.allocations(), 100u);
  EXPECT_GE(test::GlobalAllocationCount() - global_before, 100u);
}

TEST(AllocCounter, ZeroForANonAllocatingSteadyStateLoop) {
  // Setup may allocate (this is the "Init" phase of every hot path)...
  BoundedVector<float> points;
  points.Init(4096);
  RingBuffer<int, 64> queue(OverflowPolicy::kDropOldest);
  FixedVector<Eigen::Vector3d, 16> corners;

  // ...the steady state may not.
  AllocationScope scope;
  double checksum = 0.0;
  for (int frame = 0; frame < 1000; ++frame) {
    points.clear();
    for (int i = 0; i < 4096; ++i) static_cast<void>(points.try_push_back(static_cast<float>(i)));
    static_cast<void>(queue.push(frame));
    if (queue.size() > 32) checksum += queue.pop().value_or(0);
    corners.clear();
    for (int c = 0; c < 16; ++c) corners.push_back(Eigen::Vector3d(c, frame, 1.0));
    core::Vector6d xi;
    xi << 0.1, 0.2, 0.3, 0.01 * frame, 0.02, 0.03;
    const Eigen::Isometry3d T = core::Se3Exp(xi);
    checksum += core::Se3Log(T)(3) + corners.back().x() + static_cast<double>(points[4095]);
  }
  DoNotOptimize(checksum);
  EXPECT_EQ(scope.allocations(), 0u);
}

// Bit by bit, for comparison with the table-driven one.
std::uint32_t BitwiseCrc32(std::span<const std::uint8_t> bytes) {
  std::uint32_t c = 0xFFFFFFFFu;
  for (const std::uint8_t b : bytes) {
    c ^= b;
    for (int k = 0; k < 8; ++k) c = (c & 1u) != 0 ? 0xEDB88320u ^ (c >> 1) : c >> 1;
  }
  return c ^ 0xFFFFFFFFu;
}

// crc32.hpp: "never allocates"; and it is the IEEE 802.3 CRC-32 (its check value).
TEST(Crc32, IsTheIeeeCrcAndNeverAllocates) {
  const std::array<std::uint8_t, 9> check = {'1', '2', '3', '4', '5', '6', '7', '8', '9'};
  std::vector<std::uint8_t> message(64 * 1024);
  for (std::size_t i = 0; i < message.size(); ++i) message[i] = static_cast<std::uint8_t>(i * 31 + 7);
  const std::uint32_t expected = BitwiseCrc32(message);

  AllocationScope scope;
  const std::uint32_t check_crc = Crc32(check);
  const std::uint32_t empty_crc = Crc32(std::span<const std::uint8_t>());
  std::uint32_t message_crc = 0;
  for (int pass = 0; pass < 100; ++pass) message_crc = Crc32(message);
  const std::uint64_t allocations = scope.allocations();

  DoNotOptimize(message_crc);
  EXPECT_EQ(allocations, 0u);
  EXPECT_EQ(check_crc, 0xCBF43926u);
  EXPECT_EQ(empty_crc, 0u);
  EXPECT_EQ(message_crc, expected);
}

// 16 bytes a step, then byte by byte: every length of tail and every start against the
// words gives the bit-by-bit CRC.
TEST(Crc32, EveryTailAndEveryMisalignmentIsTheBitwiseCrc) {
  std::vector<std::uint8_t> message(64);
  for (std::size_t i = 0; i < message.size(); ++i) message[i] = static_cast<std::uint8_t>(i * 97 + 5);
  const std::span<const std::uint8_t> all(message);
  for (std::size_t start = 0; start < 8; ++start) {
    for (std::size_t length = 0; start + length <= all.size(); ++length) {
      const auto part = all.subspan(start, length);
      ASSERT_EQ(Crc32(part), BitwiseCrc32(part)) << start << " " << length;
    }
  }
}

// A file's CRC taken over its parts (the checkpoint's snapshot: the mapper's bytes, then the
// session's) is the CRC of the whole, wherever it is cut.
TEST(Crc32, ContinuedOverPartsIsTheCrcOfTheWhole) {
  std::vector<std::uint8_t> message(1000);
  for (std::size_t i = 0; i < message.size(); ++i) message[i] = static_cast<std::uint8_t>(i * 13 + 1);
  const std::uint32_t whole = Crc32(message);
  for (std::size_t cut : {std::size_t{0}, std::size_t{1}, std::size_t{499}, std::size_t{1000}}) {
    const std::span<const std::uint8_t> all(message);
    EXPECT_EQ(Crc32Continue(Crc32(all.first(cut)), all.subspan(cut)), whole) << cut;
  }
}

}  // namespace
}  // namespace msgraphs
