// SPDX-License-Identifier: MIT
// Per-stage wall time of every keyframe a LocalMapper maps, and how it grows with the map: the
// tables msgraphs_slam prints for one robot and msgraphs_collab for each robot of a fleet
// (issue 19's bound: keyframe p99 at 4,000 keyframes against its figure at 300, resident set
// flat after warm-up). A tool's measurement, not the mapper's: it allocates as it records.
#pragma once

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdio>
#include <vector>

#include "msgraphs/core/slam/local_mapper.hpp"

namespace msgraphs::tools {

class KeyframeTiming final : public core::StageObserver {
 public:
  /// The growth table's runs: 300 keyframes, the map size the bound is stated against.
  static constexpr std::size_t kGrowthKeyframes = 300;

  void KeyframeStarted() override;
  void StageEnded(core::MapperStage stage) override;
  /// A sweep that was not a keyframe took this long in AddScan.
  void Sweep(double ms) { sweeps_.push_back(ms); }

  /// Every mapped keyframe's total, in order.
  const std::vector<double>& total() const { return total_; }
  /// The p99 of the keyframes [first, last) (0 when empty).
  double TotalP99(std::size_t first, std::size_t last) const;
  /// The resident set after each full run of kGrowthKeyframes keyframes, in MB.
  const std::vector<double>& rss_mb() const { return rss_mb_; }
  double last_rss_mb() const { return last_rss_mb_; }

  /// The percentiles per stage, the growth tables and the sweeps, to `out`.
  void Print(std::FILE* out) const;

  /// The process's resident set now (Linux /proc; 0 where it cannot be read). In a fleet run in
  /// one process it is the whole fleet's.
  static double ResidentMb();
  /// The p-quantile by rank (nearest rank from below), 0 for an empty set.
  static double Percentile(std::vector<double> v, double p);

 private:
  using Clock = std::chrono::steady_clock;
  static constexpr std::size_t kStages = static_cast<std::size_t>(core::MapperStage::kCount);
  std::array<std::vector<double>, kStages> stages_;
  std::vector<double> total_, sweeps_, rss_mb_;
  std::array<double, kStages> pending_{};
  double last_rss_mb_ = 0;
  Clock::time_point start_, last_;
  bool active_ = false;
};

}  // namespace msgraphs::tools
