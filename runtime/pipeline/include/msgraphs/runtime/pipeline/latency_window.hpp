// SPDX-License-Identifier: MIT
// Latency samples in milliseconds, the newest `capacity` kept, and their percentiles for the
// node's status line. The SLAM thread reads p50 and p99 of its keyframe latency after every
// keyframe, so the window and the scratch its percentiles select in are allocated once, at
// construction: Add and Percentile allocate nothing (tests/runtime/latency_window_test.cpp).
// One thread uses a window (not thread-safe).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace msgraphs::runtime {

class LatencyWindow {
 public:
  explicit LatencyWindow(std::size_t capacity);
  void Add(double ms);
  /// The nearest-rank percentile of the samples kept, p in [0, 1] (1: the largest); 0 when
  /// empty. O(samples) (a selection, not a sort).
  double Percentile(double p);
  std::uint64_t count() const { return count_; }

 private:
  std::vector<double> values_;
  std::vector<double> scratch_;
  std::uint64_t count_ = 0;
};

}  // namespace msgraphs::runtime
