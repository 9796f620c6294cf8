// SPDX-License-Identifier: MIT
#include "msgraphs/runtime/pipeline/latency_window.hpp"

#include <algorithm>
#include <cmath>

namespace msgraphs::runtime {

LatencyWindow::LatencyWindow(std::size_t capacity)
    : values_(std::max<std::size_t>(1, capacity)), scratch_(std::max<std::size_t>(1, capacity)) {}

void LatencyWindow::Add(double ms) {
  values_[count_ % values_.size()] = ms;
  ++count_;
}

double LatencyWindow::Percentile(double p) {
  const std::size_t n = static_cast<std::size_t>(std::min<std::uint64_t>(count_, values_.size()));
  if (n == 0) return 0;
  const double q = std::isfinite(p) ? std::clamp(p, 0.0, 1.0) : 1.0;
  // Nearest rank: the smallest sample with at least q of them at or below it.
  const auto rank = static_cast<std::size_t>(std::ceil(q * static_cast<double>(n)));
  const std::size_t k = rank == 0 ? 0 : rank - 1;
  std::copy_n(values_.begin(), n, scratch_.begin());
  const auto end = scratch_.begin() + static_cast<std::ptrdiff_t>(n);
  std::nth_element(scratch_.begin(), scratch_.begin() + static_cast<std::ptrdiff_t>(k), end);
  return scratch_[k];
}

}  // namespace msgraphs::runtime
