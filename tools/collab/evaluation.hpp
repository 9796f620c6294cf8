// SPDX-License-Identifier: MIT
// msgraphs_collab's evaluation against the ground truth, for every robot and every view (robot
// A's estimate of robot B, every ordered pair A != B):
// - each robot's own map: its keyframes against its truth interpolated at their stamps
//   (tools/ate.hpp); that alignment is the robot's true map-to-world transform;
// - each view: merged at the end, the mission time of the first merge, every later change, the
//   origin error (A's estimate of B's map frame against the truth, from both robots' own
//   alignments) and a verdict: wrong beyond --wrong-origin-m or --wrong-origin-deg;
// - each viewer's aggregated ATE: every robot it merged, through its estimated origins;
// - the accepted matches against the truth.
// A robot without truth at its keyframes is never dropped: its ATE fails with the reason, and
// every figure that needs it says so (views "unchecked", aggregates failed).
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "evaluation_config.hpp"
#include "merge_tracker.hpp"
#include "mission.hpp"
#include "msgraphs/core/collab/collab_session.hpp"
#include "msgraphs/tools/aggregated_ate.hpp"
#include "msgraphs/tools/ate.hpp"
#include "msgraphs/tools/truth_pairing.hpp"
#include "msgraphs/tools/tum.hpp"

namespace msgraphs::tools::collab {

enum class Verdict { kRight, kWrong, kNotMerged, kUnchecked };
/// "right", "wrong", "not merged", "unchecked".
const char* Describe(Verdict v);
/// "right", "wrong", "not_merged", "unchecked" (JSON).
const char* Key(Verdict v);

struct RobotEvaluation {
  int robot = 0;  ///< id
  double start_delay_s = 0;
  const char* start_delay_source = "none";  ///< "none", "mission.txt" or "--delay-s"
  std::vector<StampedPose> keyframes;       ///< own map frame, own recording clock
  TruthTrajectory truth;
  AteResult own;  ///< own keyframes against own truth; T_truth_estimate is T_world_map
};

struct OriginError {
  bool checked = false;
  std::string reason;  ///< why not checked
  double translation_m = 0, xy_m = 0, z_m = 0, rotation_deg = 0;
};

struct ViewEvaluation {
  int viewer = 0, robot = 0;  ///< ids: the viewer's estimate of robot
  bool merged = false;        ///< at the end
  ViewHistory history;
  Eigen::Isometry3d T_viewer_robot = Eigen::Isometry3d::Identity();  ///< when merged
  OriginError origin;
  /// The worst origin error while merged, over every exchange, and when it was first wrong
  /// (a wrong merge undone later still counts as wrong).
  OriginError worst_origin;
  std::optional<double> first_wrong_s;
  Verdict verdict = Verdict::kNotMerged;
  std::size_t factors = 0;
  std::size_t matches_accepted = 0, matches_wrong = 0, matches_unchecked = 0;
  std::optional<core::CollabPeerStats> peer_stats;  ///< room-based modes only
};

struct ViewAte {
  int viewer = 0;
  AggregatedAte ate;
  /// Every robot the viewer merged (itself first), its keyframes in the viewer's frame.
  std::vector<std::pair<int, std::vector<StampedPose>>> in_view;
};

struct MatchStatistics {
  std::uint64_t proposed = 0, rejected_fine = 0, checked_anchored = 0, rejected_anchored = 0,
                rejected_consistency = 0;
  std::uint64_t accepted = 0, wrong = 0;
  std::uint64_t unchecked = 0;  ///< accepted, but a robot's truth alignment failed
};

struct ViewTotals {
  std::size_t views = 0, merged = 0, right = 0, wrong = 0, unchecked = 0, not_merged = 0;
};

struct Evaluation {
  EvaluationConfig config;
  std::vector<RobotEvaluation> robots;  ///< by index
  std::vector<ViewEvaluation> views;    ///< viewer-major, every ordered pair
  std::vector<ViewAte> view_ate;        ///< by viewer index
  MatchStatistics matches;
  ViewTotals totals() const;
  const ViewEvaluation* view(int viewer, int robot) const;
};

Evaluation Evaluate(const Mission& mission,
                    const MergeTracker& tracker,
                    const EvaluationConfig& config);

}  // namespace msgraphs::tools::collab
