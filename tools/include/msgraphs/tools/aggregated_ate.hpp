// SPDX-License-Identifier: MIT
// The aggregated ATE of one robot's view of the fleet: every robot it merged, its keyframes
// brought into the view's frame through the view's estimated origins, each keyframe paired with
// its own robot's truth (robots' clocks differ: stamps are never compared across robots), then
// one SE(3) alignment of all of them to the truth.
//
// Every robot of the fleet is listed, as a member (with its paired and unpaired counts) or as
// missing with the reason. A merged robot with too few keyframes paired with its truth (under 3,
// or under PairingConfig::min_paired_fraction of them) makes the aggregate fail (ok() false): it
// is never just left out of the average, nor stands in it for a trajectory it barely covers. A
// robot that is not merged is listed as missing but does not fail the ATE of what was merged; the
// merge itself is the figure that fails. Host tools only; allocates.
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <string>
#include <vector>

#include "msgraphs/tools/ate.hpp"
#include "msgraphs/tools/truth_pairing.hpp"
#include "msgraphs/tools/tum.hpp"

namespace msgraphs::tools {

struct AggregatedMember {
  int robot = 0;
  PairCounts pairs;
};

struct AggregatedMissing {
  int robot = 0;
  bool merged = false;  ///< merged, but without enough truth: the aggregate fails
  std::string reason;
};

struct AggregatedAte {
  AteResult ate;  ///< over the members' paired keyframes
  std::vector<AggregatedMember> members;
  std::vector<AggregatedMissing> missing;

  /// A merged robot is missing (no truth to score it against).
  bool truth_incomplete() const {
    return std::any_of(missing.begin(), missing.end(),
                       [](const AggregatedMissing& m) { return m.merged; });
  }
  /// The figure stands: aligned, and every merged robot in it.
  bool ok() const { return ate.ok && !truth_incomplete(); }
  /// Why !ok(), for reports.
  std::string failure() const {
    if (ok()) return "";
    std::string out;
    for (const AggregatedMissing& m : missing) {
      if (!m.merged) continue;
      out += (out.empty() ? "" : "; ") + std::string("robot ") + std::to_string(m.robot) +
             " merged but " + m.reason;
    }
    if (!ate.ok) out += (out.empty() ? "" : "; ") + std::string(ate.error);
    return out;
  }
  /// "robot 1 250 keyframes, robot 2 248 (2 after the truth); missing: robot 3 (not merged)".
  std::string Describe() const {
    std::string out;
    for (const AggregatedMember& m : members) {
      out += (out.empty() ? "" : ", ") + std::string("robot ") + std::to_string(m.robot) + " " +
             std::to_string(m.pairs.paired) + " keyframes";
      if (m.pairs.unpaired_total() > 0) out += " (unpaired: " + m.pairs.DescribeUnpaired() + ")";
    }
    for (std::size_t i = 0; i < missing.size(); ++i) {
      out += i > 0 ? ", " : out.empty() ? "missing: " : "; missing: ";
      out += "robot " + std::to_string(missing[i].robot) + " (" + missing[i].reason + ")";
    }
    return out;
  }
};

class AggregatedAteBuilder {
 public:
  /// A robot the view did not merge (or could not place): listed, not scored.
  void AddNotMerged(int robot, std::string reason = "not merged") {
    missing_.push_back({robot, false, std::move(reason)});
  }

  /// A merged robot: `keyframes_in_view` are its keyframes in the view's frame, stamped by its
  /// own clock; `truth` its own truth (nullptr or empty when there is none).
  void AddMerged(int robot,
                 const std::vector<StampedPose>& keyframes_in_view,
                 const TruthTrajectory* truth) {
    if (truth == nullptr || truth->empty()) {
      missing_.push_back({robot, true, "has no ground truth"});
      return;
    }
    PairedPoses paired = PairWithTruth(keyframes_in_view, *truth);
    if (TooFewPaired(paired.counts, truth->config())) {
      missing_.push_back({robot, true,
                          "has " + std::to_string(paired.counts.paired) + " of " +
                              std::to_string(keyframes_in_view.size()) +
                              " keyframes paired with its truth (unpaired: " +
                              paired.counts.DescribeUnpaired() + ")"});
      return;
    }
    members_.push_back({robot, paired.counts});
    for (const StampedPose& p : paired.estimate) estimate_.push_back(p.T.translation());
    for (const StampedPose& p : paired.truth) truth_.push_back(p.T.translation());
  }

  AggregatedAte Finish() const {
    AggregatedAte out;
    out.ate = AteOfPairs(estimate_, truth_);
    out.ate.pairs = {};  // the members' counts (missing robots are listed with theirs)
    for (const AggregatedMember& m : members_) out.ate.pairs.Add(m.pairs);
    out.members = members_;
    out.missing = missing_;
    std::sort(out.members.begin(), out.members.end(),
              [](const auto& a, const auto& b) { return a.robot < b.robot; });
    std::sort(out.missing.begin(), out.missing.end(),
              [](const auto& a, const auto& b) { return a.robot < b.robot; });
    return out;
  }

 private:
  std::vector<Eigen::Vector3d> estimate_, truth_;
  std::vector<AggregatedMember> members_;
  std::vector<AggregatedMissing> missing_;
};

}  // namespace msgraphs::tools
