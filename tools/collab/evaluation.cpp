// SPDX-License-Identifier: MIT
#include "evaluation.hpp"

#include <cmath>
#include <numbers>

#include "peer_stats_report.hpp"

namespace msgraphs::tools::collab {
namespace {

double Degrees(const Eigen::Matrix3d& R) {
  return Eigen::AngleAxisd(R).angle() * 180.0 / std::numbers::pi;
}

// The truth of robot b's map frame in robot a's, from both robots' own alignments.
std::optional<Eigen::Isometry3d> TrueOrigin(const RobotEvaluation& a, const RobotEvaluation& b) {
  if (!a.own.ok || !b.own.ok) return std::nullopt;
  return a.own.T_truth_estimate.inverse() * b.own.T_truth_estimate;
}

OriginError CheckOrigin(const RobotEvaluation& a,
                        const RobotEvaluation& b,
                        const Eigen::Isometry3d& T_a_b) {
  OriginError e;
  const auto truth = TrueOrigin(a, b);
  if (!truth) {
    const RobotEvaluation& without = a.own.ok ? b : a;
    e.reason =
        "robot " + std::to_string(without.robot) + " has no truth alignment: " + without.own.error;
    return e;
  }
  const Eigen::Isometry3d d = truth->inverse() * T_a_b;
  e.checked = true;
  e.translation_m = d.translation().norm();
  e.xy_m = d.translation().head<2>().norm();
  e.z_m = d.translation().z();
  e.rotation_deg = Degrees(d.linear());
  return e;
}

void CountSessionMatches(const Mission& mission, MatchStatistics& m) {
  for (const auto& r : mission.robots) {
    if (mission.keyframes) {
      m.proposed += r->baseline.proposals;
      m.rejected_fine += r->baseline.rejected_fine;
      m.rejected_consistency += r->baseline.rejected_consistency;
      continue;
    }
    const core::CollabSessionStats& st = r->session.stats();
    m.proposed += st.proposals;
    m.rejected_fine += st.rejected_fine;
    m.rejected_consistency += st.rejected_consistency;
    m.rejected_anchored += st.rejected_anchored;
    m.checked_anchored += st.checked_anchored;
  }
}

}  // namespace

const char* Describe(Verdict v) {
  switch (v) {
    case Verdict::kRight:
      return "right";
    case Verdict::kWrong:
      return "WRONG";
    case Verdict::kNotMerged:
      return "not merged";
    case Verdict::kUnchecked:
      return "unchecked";
  }
  return "?";
}

const char* Key(Verdict v) {
  switch (v) {
    case Verdict::kRight:
      return "right";
    case Verdict::kWrong:
      return "wrong";
    case Verdict::kNotMerged:
      return "not_merged";
    case Verdict::kUnchecked:
      return "unchecked";
  }
  return "?";
}

ViewTotals Evaluation::totals() const {
  ViewTotals t;
  for (const ViewEvaluation& v : views) {
    ++t.views;
    if (v.merged) ++t.merged;
    switch (v.verdict) {
      case Verdict::kRight:
        ++t.right;
        break;
      case Verdict::kWrong:
        ++t.wrong;
        break;
      case Verdict::kUnchecked:
        ++t.unchecked;
        break;
      case Verdict::kNotMerged:
        ++t.not_merged;
        break;
    }
  }
  return t;
}

const ViewEvaluation* Evaluation::view(int viewer, int robot) const {
  for (const ViewEvaluation& v : views) {
    if (v.viewer == viewer && v.robot == robot) return &v;
  }
  return nullptr;
}

Evaluation Evaluate(const Mission& mission,
                    const MergeTracker& tracker,
                    const EvaluationConfig& config) {
  Evaluation out;
  out.config = config;
  for (const auto& r : mission.robots) {
    RobotEvaluation e;
    e.robot = r->id();
    e.start_delay_s = r->delay_s;
    e.start_delay_source = r->delay_source;
    e.keyframes = Keyframes(*r);
    e.truth = TruthTrajectory(r->truth);
    e.own = ComputeAte(e.keyframes, e.truth);
    out.robots.push_back(std::move(e));
  }
  for (const auto& a : mission.robots) {
    const RobotEvaluation& ea = out.robots[static_cast<std::size_t>(a->index)];
    ViewAte view_ate;
    view_ate.viewer = a->id();
    AggregatedAteBuilder aggregated;
    aggregated.AddMerged(a->id(), ea.keyframes, &ea.truth);
    view_ate.in_view.push_back({a->id(), ea.keyframes});
    for (const auto& b : mission.robots) {
      if (a == b) continue;
      const RobotEvaluation& eb = out.robots[static_cast<std::size_t>(b->index)];
      ViewEvaluation v;
      v.viewer = a->id();
      v.robot = b->id();
      v.merged = mission.Merged(*a, b->index);
      v.history = tracker.at(a->index, b->index);
      v.factors = mission.Factors(*a, b->index);
      if (!mission.keyframes) v.peer_stats = FindPeerStats(a->session, b->id());
      const auto truth = TrueOrigin(ea, eb);
      for (const core::RoomMatch& m : mission.Accepted(*a, b->index)) {
        ++v.matches_accepted;
        if (!truth) {
          ++v.matches_unchecked;
          continue;
        }
        const Eigen::Isometry3d e = truth->inverse() * m.T_a_b;
        if (e.translation().head<2>().norm() > kWrongMatch_m ||
            Eigen::AngleAxisd(e.linear()).angle() > kWrongMatch_rad)
          ++v.matches_wrong;
      }
      out.matches.accepted += v.matches_accepted;
      out.matches.wrong += v.matches_wrong;
      out.matches.unchecked += v.matches_unchecked;
      // Every merged moment, against the truth.
      for (const MergedEstimate& m : v.history.estimates) {
        const OriginError e = CheckOrigin(ea, eb, m.T_viewer_robot);
        if (!e.checked) continue;
        if (!v.worst_origin.checked || e.translation_m > v.worst_origin.translation_m) {
          const double rotation = std::max(v.worst_origin.rotation_deg, e.rotation_deg);
          v.worst_origin = e;
          v.worst_origin.rotation_deg = rotation;
        }
        v.worst_origin.rotation_deg = std::max(v.worst_origin.rotation_deg, e.rotation_deg);
        if (!v.first_wrong_s && (e.translation_m > config.wrong_origin_m || e.rotation_deg > config.wrong_origin_deg))
          v.first_wrong_s = m.mission_time_s;
      }
      if (!v.merged) {
        v.verdict = v.first_wrong_s ? Verdict::kWrong : Verdict::kNotMerged;
        v.origin.reason = "not merged";
        aggregated.AddNotMerged(b->id());
      } else {
        v.T_viewer_robot = mission.Origin(*a, b->index);
        v.origin = CheckOrigin(ea, eb, v.T_viewer_robot);
        v.verdict = !v.origin.checked ? Verdict::kUnchecked
                    : v.first_wrong_s || v.origin.translation_m > config.wrong_origin_m ||
                            v.origin.rotation_deg > config.wrong_origin_deg
                        ? Verdict::kWrong
                        : Verdict::kRight;
        std::vector<StampedPose> in_a;
        for (const StampedPose& p : eb.keyframes) in_a.push_back({p.t, v.T_viewer_robot * p.T});
        aggregated.AddMerged(b->id(), in_a, &eb.truth);
        view_ate.in_view.push_back({b->id(), std::move(in_a)});
      }
      out.views.push_back(std::move(v));
    }
    view_ate.ate = aggregated.Finish();
    out.view_ate.push_back(std::move(view_ate));
  }
  CountSessionMatches(mission, out.matches);
  return out;
}

}  // namespace msgraphs::tools::collab
