// SPDX-License-Identifier: MIT
#include "msgraphs/core/slam/fitness_gate.hpp"
#include "msgraphs/base/snapshot_archive.hpp"

#include <algorithm>
#include <cmath>

namespace msgraphs::core {

Status FitnessGateConfig::Validate() const {
  if (!std::isfinite(floor_m2) || !(floor_m2 > 0)) {
    return Error{Errc::kInvalidArgument, "fitness gate: floor_m2 must be finite and > 0"};
  }
  if (window == 0 || min_samples == 0 || min_samples > window) {
    return Error{Errc::kInvalidArgument, "fitness gate: need 0 < min_samples <= window"};
  }
  if (!std::isfinite(outlier_z) || outlier_z < 0) {
    return Error{Errc::kInvalidArgument, "fitness gate: outlier_z must be finite and >= 0"};
  }
  return Ok();
}

Status FitnessGate::Init(const FitnessGateConfig& config) {
  if (auto s = config.Validate(); !s) return s;
  config_ = config;
  ring_.assign(config.window, 0.0);
  scratch_.assign(config.window, 0.0);
  Reset();
  return Ok();
}

void FitnessGate::Reset() {
  next_ = 0;
  count_ = 0;
  ignored_ = 0;
}

void FitnessGate::Add(double fitness_m2) {
  if (ring_.empty()) return;  // not initialised
  if (!std::isfinite(fitness_m2) || fitness_m2 < 0) {
    ++ignored_;
    return;
  }
  ring_[next_] = fitness_m2;
  next_ = (next_ + 1) % ring_.size();
  count_ = std::min(count_ + 1, ring_.size());
}

double FitnessGate::Limit() {
  if (count_ < config_.min_samples || !(config_.outlier_z > 0)) return config_.floor_m2;
  const auto first = scratch_.begin();
  const auto last = first + static_cast<std::ptrdiff_t>(count_);
  std::copy_n(ring_.begin(), count_, first);
  // Upper median: for an even count the larger middle value (the bound errs wider, by one sample).
  const auto mid = first + static_cast<std::ptrdiff_t>(count_ / 2);
  std::nth_element(first, mid, last);
  const double median = *mid;
  for (auto it = first; it != last; ++it) *it = std::fabs(*it - median);
  std::nth_element(first, mid, last);
  const double mad = *mid;
  // 1.4826 makes the MAD a standard deviation for normal data (1 / Phi^-1(3/4)).
  const double bound = median + config_.outlier_z * 1.4826 * mad;
  return std::max(config_.floor_m2, bound);
}


template <class Archive>
void FitnessGate::Io(Archive& ar) {
  IoSameSize(ar, ring_.size());
  if (ar.failed() || ring_.empty()) return;
  ar(ring_.data(), ring_.size());
  IoCount(ar, next_, ring_.size() - 1);
  IoCount(ar, count_, ring_.size());
  ar(ignored_);
  if constexpr (Archive::kLoading) {
    for (double f : ring_)
      if (!std::isfinite(f) || f < 0) ar.Fail();  // what Add lets in
  }
}

void FitnessGate::Save(SnapshotWriter& w) const { const_cast<FitnessGate*>(this)->Io(w); }
void FitnessGate::Load(SnapshotReader& r) { Io(r); }

}  // namespace msgraphs::core
