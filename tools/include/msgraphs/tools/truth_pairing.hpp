// SPDX-License-Identifier: MIT
// The ground truth at an estimate's stamp, interpolated between the two truth samples that
// bracket it (position linear, rotation slerp), or the reason there is none.
//
// Why interpolate rather than take the nearest sample: truth recorded at 50 Hz and keyframes
// stamped at 10 Hz scan ends can miss every sample by more than any fixed association window,
// and a robot whose keyframes all miss would silently leave the evaluation. Truth written by
// other tools may come at any rate (10 Hz to 1 kHz), so nothing here assumes one: the gap
// limit is derived from the truth's own median sample period.
//
// A stamp is paired only when it lies inside the truth's time span and its bracketing samples
// are no further apart than the gap limit; every other stamp is counted with its reason.
// Host tools only; allocates (copies the truth once).
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "msgraphs/tools/tum.hpp"

namespace msgraphs::tools {

/// Why an estimate's stamp got no truth pose.
enum class Unpaired : std::uint8_t {
  kBeforeTruth,  ///< earlier than the first truth sample
  kAfterTruth,   ///< later than the last truth sample
  kInGap,        ///< its bracketing samples are further apart than the gap limit
  kBeyondMaxDt,  ///< no truth sample within the optional stricter limit (PairingConfig::max_dt_s)
  kNoTruth,      ///< the truth has fewer than two samples: nothing to interpolate
  kBadStamp,     ///< a non-finite stamp
};
inline constexpr std::size_t kUnpairedReasons = 6;

/// For reports: "before the truth", ...
inline const char* Describe(Unpaired reason) {
  static constexpr const char* kText[kUnpairedReasons] = {
      "before the truth",  "after the truth",           "in a gap of the truth",
      "beyond --max-dt-s", "truth has under 2 samples", "non-finite stamp"};
  return kText[static_cast<std::size_t>(reason)];
}
/// For machine-readable summaries: "before_truth", ...
inline const char* Key(Unpaired reason) {
  static constexpr const char* kKeys[kUnpairedReasons] = {
      "before_truth", "after_truth", "in_gap", "beyond_max_dt", "no_truth", "bad_stamp"};
  return kKeys[static_cast<std::size_t>(reason)];
}

struct PairingConfig {
  /// Bracketing samples further apart than this many median sample periods are a gap in the
  /// truth. 2.5: one dropped sample (2 periods, plus some jitter) is bridged, two in a row are a
  /// gap. A documented configuration value, the same for every truth rate.
  double gap_periods = 2.5;
  /// Optional stricter limit (0 = none): a stamp is paired only when a truth sample lies within
  /// this many seconds of it. msgraphs_ate's and msgraphs_fleet_report's --max-dt-s.
  double max_dt_s = 0;
  /// An ATE over fewer than this fraction of an estimate's poses would stand for a trajectory
  /// it mostly does not cover: it fails instead (ate.hpp, aggregated_ate.hpp). A documented
  /// configuration value: most of a trajectory must be scored for its figure to stand.
  double min_paired_fraction = 0.5;
};

/// How many estimate stamps got a truth pose, and why the others did not.
struct PairCounts {
  std::size_t paired = 0;
  std::array<std::size_t, kUnpairedReasons> unpaired{};

  std::size_t unpaired_total() const {
    std::size_t n = 0;
    for (std::size_t k : unpaired) n += k;
    return n;
  }
  std::size_t total() const { return paired + unpaired_total(); }
  std::size_t count(Unpaired reason) const { return unpaired[static_cast<std::size_t>(reason)]; }
  void Count(Unpaired reason) { ++unpaired[static_cast<std::size_t>(reason)]; }
  void Add(const PairCounts& other) {
    paired += other.paired;
    for (std::size_t k = 0; k < kUnpairedReasons; ++k) unpaired[k] += other.unpaired[k];
  }
  /// "12 before the truth, 3 in a gap of the truth", or "none" when every stamp was paired.
  std::string DescribeUnpaired() const {
    std::string out;
    for (std::size_t k = 0; k < kUnpairedReasons; ++k) {
      if (unpaired[k] == 0) continue;
      if (!out.empty()) out += ", ";
      out += std::to_string(unpaired[k]) + " " + Describe(static_cast<Unpaired>(k));
    }
    return out.empty() ? "none" : out;
  }
};

/// One robot's truth, sorted, with the sample period and gap limit derived from it.
class TruthTrajectory {
 public:
  struct Lookup {
    bool ok = false;
    Unpaired reason = Unpaired::kNoTruth;  ///< when !ok
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  };

  TruthTrajectory() = default;
  explicit TruthTrajectory(std::vector<StampedPose> samples, PairingConfig config = {})
      : samples_(std::move(samples)), config_(config) {
    std::stable_sort(samples_.begin(), samples_.end(),
                     [](const StampedPose& a, const StampedPose& b) { return a.t < b.t; });
    std::vector<double> periods;
    for (std::size_t i = 1; i < samples_.size(); ++i) {
      const double dt = samples_[i].t - samples_[i - 1].t;
      if (dt > 0) periods.push_back(dt);  // duplicate stamps are not a period
    }
    if (!periods.empty()) {
      // The median: robust to the gaps themselves and to jitter.
      const auto middle = periods.begin() + static_cast<std::ptrdiff_t>(periods.size() / 2);
      std::nth_element(periods.begin(), middle, periods.end());
      median_period_s_ = *middle;
    }
    gap_limit_s_ = config_.gap_periods * median_period_s_;
  }

  /// The truth at `t`: interpolated between the bracketing samples, or why not.
  Lookup At(double t) const {
    Lookup out;
    if (!std::isfinite(t)) {
      out.reason = Unpaired::kBadStamp;
      return out;
    }
    if (samples_.size() < 2 || !(median_period_s_ > 0)) {
      out.reason = Unpaired::kNoTruth;
      return out;
    }
    if (t < samples_.front().t) {
      out.reason = Unpaired::kBeforeTruth;
      return out;
    }
    if (t > samples_.back().t) {
      out.reason = Unpaired::kAfterTruth;
      return out;
    }
    // b: the first sample at or after t; a: the one before (b itself at the first stamp).
    auto it = std::lower_bound(samples_.begin(), samples_.end(), t,
                               [](const StampedPose& s, double v) { return s.t < v; });
    const StampedPose& b = *it;
    // A stamp exactly on a sample needs no neighbour (the sample before it may be across a gap).
    const StampedPose& a = it == samples_.begin() || b.t == t ? b : *(it - 1);
    if (b.t - a.t > gap_limit_s_) {
      out.reason = Unpaired::kInGap;
      return out;
    }
    if (config_.max_dt_s > 0 && std::min(t - a.t, b.t - t) > config_.max_dt_s) {
      out.reason = Unpaired::kBeyondMaxDt;
      return out;
    }
    const double f = b.t > a.t ? (t - a.t) / (b.t - a.t) : 0.0;
    out.T.translation() = a.T.translation() + f * (b.T.translation() - a.T.translation());
    out.T.linear() = Eigen::Quaterniond(a.T.linear())
                         .slerp(f, Eigen::Quaterniond(b.T.linear()))
                         .normalized()
                         .toRotationMatrix();
    out.ok = true;
    return out;
  }

  const std::vector<StampedPose>& samples() const { return samples_; }
  bool empty() const { return samples_.empty(); }
  double median_period_s() const { return median_period_s_; }
  double gap_limit_s() const { return gap_limit_s_; }
  const PairingConfig& config() const { return config_; }

 private:
  std::vector<StampedPose> samples_;
  PairingConfig config_;
  double median_period_s_ = 0;
  double gap_limit_s_ = 0;
};

/// An estimate's poses that got a truth pose, each beside it (same stamp), and the counts.
struct PairedPoses {
  std::vector<StampedPose> estimate, truth;
  PairCounts counts;
};

inline PairedPoses PairWithTruth(const std::vector<StampedPose>& estimate,
                                 const TruthTrajectory& truth) {
  PairedPoses out;
  for (const StampedPose& e : estimate) {
    const TruthTrajectory::Lookup l = truth.At(e.t);
    if (!l.ok) {
      out.counts.Count(l.reason);
      continue;
    }
    ++out.counts.paired;
    out.estimate.push_back(e);
    out.truth.push_back({e.t, l.T});
  }
  return out;
}

}  // namespace msgraphs::tools
