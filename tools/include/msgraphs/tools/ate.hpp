// SPDX-License-Identifier: MIT
// The absolute trajectory error, as evo's `evo_ape tum --align` reports it: every estimate pose
// paired with the truth interpolated at its stamp (truth_pairing.hpp), the estimate aligned to
// the truth by one rigid SE(3) Umeyama fit, then RMSE / mean / median / max of the position
// errors. The result says how many poses were paired and why the others were not, so that a
// caller never reports an ATE over a silently shrunken set. Host tools only; allocates.
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <span>
#include <vector>

#include "msgraphs/core/geometry/umeyama.hpp"
#include "msgraphs/tools/truth_pairing.hpp"
#include "msgraphs/tools/tum.hpp"

namespace msgraphs::tools {

/// Fewer paired poses than this cannot be aligned (AlignUmeyama's minimum): the ATE fails.
inline constexpr std::size_t kMinPairedPoses = 3;

struct AteResult {
  bool ok = false;
  const char* error = "";  ///< why not ok (static text)
  PairCounts pairs;        ///< paired, and unpaired by reason
  double rmse = 0, mean = 0, median = 0, max = 0;
  Eigen::Isometry3d T_truth_estimate = Eigen::Isometry3d::Identity();
  std::size_t poses() const { return pairs.paired; }
};

/// The ATE of positions already paired one to one (`estimate[i]` is `truth[i]`'s pose).
inline AteResult AteOfPairs(std::span<const Eigen::Vector3d> estimate,
                            std::span<const Eigen::Vector3d> truth) {
  AteResult out;
  out.pairs.paired = std::min(estimate.size(), truth.size());
  if (estimate.size() != truth.size()) {
    out.error = "estimate and truth differ in length";
    return out;
  }
  if (estimate.size() < kMinPairedPoses) {
    out.error = "fewer than 3 poses paired with the truth";
    return out;
  }
  auto T = core::AlignUmeyama(estimate, truth);
  if (!T) {
    out.error = T.error().detail;
    return out;
  }
  std::vector<double> errors;
  errors.reserve(estimate.size());
  double sum = 0, sum2 = 0;
  for (std::size_t i = 0; i < estimate.size(); ++i) {
    const double e = (*T * estimate[i] - truth[i]).norm();
    errors.push_back(e);
    sum += e;
    sum2 += e * e;
  }
  std::sort(errors.begin(), errors.end());
  const auto n = static_cast<double>(errors.size());
  out.rmse = std::sqrt(sum2 / n);
  out.mean = sum / n;
  out.median = errors[errors.size() / 2];
  out.max = errors.back();
  out.T_truth_estimate = *T;
  out.ok = true;
  return out;
}

/// The ATE of poses already paired with their truth (PairWithTruth), with its counts.
inline AteResult AteOfPaired(const PairedPoses& paired) {
  std::vector<Eigen::Vector3d> a, b;
  a.reserve(paired.estimate.size());
  b.reserve(paired.truth.size());
  for (const StampedPose& p : paired.estimate) a.push_back(p.T.translation());
  for (const StampedPose& p : paired.truth) b.push_back(p.T.translation());
  AteResult out = AteOfPairs(a, b);
  out.pairs = paired.counts;
  return out;
}

/// Too few of `counts` paired for a figure to stand for the whole estimate (see
/// kMinPairedPoses and PairingConfig::min_paired_fraction).
inline bool TooFewPaired(const PairCounts& counts, const PairingConfig& config) {
  return counts.paired < kMinPairedPoses ||
         static_cast<double>(counts.paired) <
             config.min_paired_fraction * static_cast<double>(counts.total());
}

/// The ATE of `estimate` against the truth interpolated at its stamps. Fails when fewer than
/// kMinPairedPoses or than min_paired_fraction of the poses are paired.
inline AteResult ComputeAte(const std::vector<StampedPose>& estimate,
                            const TruthTrajectory& truth) {
  const PairedPoses paired = PairWithTruth(estimate, truth);
  if (paired.counts.paired >= kMinPairedPoses && TooFewPaired(paired.counts, truth.config())) {
    AteResult out;
    out.pairs = paired.counts;
    out.error = "fewer than min_paired_fraction (default half) of the poses paired with the truth";
    return out;
  }
  return AteOfPaired(paired);
}

inline AteResult ComputeAte(const std::vector<StampedPose>& estimate,
                            const std::vector<StampedPose>& truth,
                            PairingConfig config = {}) {
  return ComputeAte(estimate, TruthTrajectory(truth, config));
}

}  // namespace msgraphs::tools
