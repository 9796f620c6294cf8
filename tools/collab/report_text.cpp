// SPDX-License-Identifier: MIT
// The text report. Its first lines keep the format tools/eval/results.py reads (robot 1's
// view); the tables after them cover every robot and every view.
#include <cstdarg>
#include <cstdio>

#include "peer_stats_report.hpp"
#include "report.hpp"

namespace msgraphs::tools::collab {
namespace {

__attribute__((format(printf, 2, 3))) void Add(std::string& out, const char* format, ...) {
  char line[2048];
  va_list args;
  va_start(args, format);
  std::vsnprintf(line, sizeof line, format, args);
  va_end(args);
  out += line;
}

std::string OriginText(const OriginError& e) {
  char b[96];
  std::snprintf(b, sizeof b, "%.3f m, %.2f deg", e.translation_m, e.rotation_deg);
  return e.checked ? b : "-";
}

std::string FirstMerge(const ViewHistory& h) {
  char b[32];
  if (!h.first_merge_s) return "never";
  std::snprintf(b, sizeof b, "%.1f s", *h.first_merge_s);
  return b;
}

void RobotOneLines(const ReportInput& in, std::string& out) {
  const Evaluation& ev = in.evaluation;
  const ViewAte& v1 = ev.view_ate.front();
  std::size_t merged = 1;
  for (const ViewEvaluation& v : ev.views) merged += v.viewer == 1 && v.merged ? 1 : 0;
  if (v1.ate.ok()) {
    Add(out,
        "robot 1 merged %zu of %zu robots; aggregated ATE %.3f m over %zu keyframes (max %.3f m)\n",
        merged, ev.robots.size(), v1.ate.ate.rmse, v1.ate.ate.poses(), v1.ate.ate.max);
  } else {
    Add(out, "robot 1 merged %zu of %zu robots; aggregated ATE FAILED: %s\n", merged,
        ev.robots.size(), v1.ate.failure().c_str());
  }
  for (const ViewEvaluation& v : ev.views) {
    if (v.viewer != 1) continue;
    if (!v.merged) {
      Add(out, "  robot %d: not merged\n", v.robot);
    } else if (!v.origin.checked) {
      Add(out, "  robot %d: origin not checked: %s (%zu factors)\n", v.robot,
          v.origin.reason.c_str(), v.factors);
    } else {
      Add(out, "  robot %d: origin error %.3f m (xy %.3f m, z %+.3f m), %.2f deg (%zu factors)\n",
          v.robot, v.origin.translation_m, v.origin.xy_m, v.origin.z_m, v.origin.rotation_deg,
          v.factors);
    }
  }
}

void RobotLines(const ReportInput& in, std::string& out) {
  Add(out, "robots (own map against own truth, interpolated at each keyframe's stamp):\n");
  for (const RobotEvaluation& r : in.evaluation.robots) {
    std::string ate;
    char b[160];
    if (r.own.ok) {
      std::snprintf(b, sizeof b, "ATE %.3f m (max %.3f m) over %zu keyframes", r.own.rmse,
                    r.own.max, r.own.poses());
      ate = b;
    } else {
      ate = std::string("ATE FAILED: ") + r.own.error;
    }
    Add(out,
        "  robot %d: start delay %.1f s (%s); %zu keyframes; %s; unpaired: %s; truth %zu samples, "
        "period %.4f s, gap limit %.4f s\n",
        r.robot, r.start_delay_s, r.start_delay_source, r.keyframes.size(), ate.c_str(),
        r.own.pairs.DescribeUnpaired().c_str(), r.truth.samples().size(), r.truth.median_period_s(),
        r.truth.gap_limit_s());
  }
  // What fed the collaborative estimate back into each own map (--feedback): the peers' walls
  // held as priors on this robot's walls at the end.
  if (in.mission.keyframes) return;
  Add(out, "feedback (%s): wall priors from peers in each local S-Graph at the end:",
      in.mission.feedback ? "on" : "off");
  for (const auto& robot : in.mission.robots) {
    const core::LocalMapperStats& s = robot->mapper.stats();
    Add(out, " robot %d %zu (refused %llu, held back disagreeing %zu);", robot->id(), s.plane_priors,
        static_cast<unsigned long long>(s.plane_priors_refused), robot->session.stats().priors_gated);
  }
  Add(out, "\n");
}

void ViewTable(const ReportInput& in, std::string& out) {
  const Evaluation& ev = in.evaluation;
  Add(out,
      "views (robot A's estimate of robot B at the end; wrong: origin off by more than %.2f m or "
      "%.2f deg):\n",
      ev.config.wrong_origin_m, ev.config.wrong_origin_deg);
  Add(out, "  %-8s %-6s %-12s %-22s %-14s %-10s %s\n", "B in A", "merged", "first merge",
      "origin error", "unmerged later", "verdict", "matches (wrong)");
  for (const ViewEvaluation& v : ev.views) {
    char label[32], matches[48];
    std::snprintf(label, sizeof label, "%d in %d", v.robot, v.viewer);
    std::snprintf(matches, sizeof matches, "%zu (%zu)%s", v.matches_accepted, v.matches_wrong,
                  v.matches_unchecked > 0 ? " unchecked" : "");
    const std::size_t unmerges = v.history.unmerges();
    char unmerged[32] = "no";
    if (unmerges > 0) std::snprintf(unmerged, sizeof unmerged, "yes (%zu x)", unmerges);
    Add(out, "  %-8s %-6s %-12s %-22s %-14s %-10s %s\n", label, v.merged ? "yes" : "no",
        FirstMerge(v.history).c_str(), OriginText(v.origin).c_str(), unmerged, Describe(v.verdict),
        matches);
    if (v.merged && !v.origin.checked)
      Add(out, "    (origin not checked: %s)\n", v.origin.reason.c_str());
    if (v.first_wrong_s)
      Add(out, "    (wrong from %.1f s: origin off by up to %.3f m, %.2f deg while merged)\n", *v.first_wrong_s,
          v.worst_origin.translation_m, v.worst_origin.rotation_deg);
  }
  for (const ViewExplanation& e : in.explanations) {
    if (!e.checked) {
      Add(out, "  why %d in %d: %s\n", e.robot, e.viewer, e.cause);
      continue;
    }
    Add(out,
        "  why %d in %d: %s; the truth: walls agree %.1f m (%.1f m weakest direction), conflict %.2f m "
        "(walls in free %.2f + %.2f, openings on walls %.2f + %.2f), %s (rank %zu of %zu); the "
        "rule now: %s, leader %.2f m from the truth; merged with %.2f m, solved %.2f m from it\n",
        e.robot, e.viewer, e.cause, e.truth.agreement.agreement_m, e.truth.agreement.constraint_m,
        e.truth.conflict_m(), e.truth.conflict_b_in_a.walls_in_free_m, e.truth.conflict_a_in_b.walls_in_free_m,
        e.truth.conflict_b_in_a.openings_on_solid_m, e.truth.conflict_a_in_b.openings_on_solid_m,
        e.proposed ? "proposed" : "NOT proposed", e.rank, e.hypotheses, core::ToString(e.decision.verdict),
        e.leader_truth_distance_m, e.merge_truth_distance_m, e.solved_truth_distance_m);
  }
  const ViewTotals t = ev.totals();
  Add(out, "views: %zu of %zu merged; %zu right, %zu wrong, %zu unchecked, %zu not merged\n",
      t.merged, t.views, t.right, t.wrong, t.unchecked, t.not_merged);
}

void ViewAteLines(const ReportInput& in, std::string& out) {
  Add(out,
      "aggregated ATE per view (every robot the view merged, through its estimated origins, one "
      "SE(3) alignment):\n");
  for (const ViewAte& v : in.evaluation.view_ate) {
    if (v.ate.ok()) {
      Add(out, "  view of robot %d: %.3f m (max %.3f m) over %zu keyframes: %s\n", v.viewer,
          v.ate.ate.rmse, v.ate.ate.max, v.ate.ate.poses(), v.ate.Describe().c_str());
    } else {
      Add(out, "  view of robot %d: FAILED: %s; %s\n", v.viewer, v.ate.failure().c_str(),
          v.ate.Describe().c_str());
    }
  }
}

void MatchLines(const ReportInput& in, std::string& out) {
  const MatchStatistics& m = in.evaluation.matches;
  Add(out,
      "room matches (all robots): %llu proposed by Scan Context, %llu rejected by fine alignment, "
      "%llu checked against a merged estimate (%llu rejected), %llu rejected by the consistency "
      "check, %llu accepted, %llu of them wrong against the truth",
      static_cast<unsigned long long>(m.proposed), static_cast<unsigned long long>(m.rejected_fine),
      static_cast<unsigned long long>(m.checked_anchored),
      static_cast<unsigned long long>(m.rejected_anchored),
      static_cast<unsigned long long>(m.rejected_consistency),
      static_cast<unsigned long long>(m.accepted), static_cast<unsigned long long>(m.wrong));
  if (m.unchecked > 0)
    Add(out, ", %llu not checked (no truth alignment)",
        static_cast<unsigned long long>(m.unchecked));
  Add(out, "\n");
  // Where competing hypotheses were weighed by the walls, or a pair stayed unmerged.
  for (const ViewEvaluation& v : in.evaluation.views) {
    if (v.peer_stats) out += PeerStatsLine(v.viewer, *v.peer_stats, v.matches_wrong);
  }
}

void DataLines(const ReportInput& in, std::string& out) {
  const Accounting& acc = in.mission.accounting;
  Add(out, "data exchanged: %.3f MB in total, %llu messages malformed\n",
      static_cast<double>(acc.Total()) / 1e6, static_cast<unsigned long long>(acc.malformed));
  for (int t = 0; t < kMessageTypes; ++t)
    Add(out, "  %-20s %10.1f kB\n", MessageTypeName(t), static_cast<double>(acc.Total(t)) / 1e3);
  for (const auto& from : in.mission.robots) {
    for (const auto& to : in.mission.robots) {
      if (from == to) continue;
      Add(out, "  robot %d -> robot %d %10.1f kB\n", from->id(), to->id(),
          static_cast<double>(acc.Link(from->index, to->index)) / 1e3);
    }
  }
}

}  // namespace

std::string TextReport(const ReportInput& in) {
  std::string out;
  Add(out, "mission %s: %zu robots, mode %s, %.1f s\n", in.options.run.c_str(),
      in.mission.robots.size(), in.options.mode_name.c_str(), in.run.run_time_s);
  RobotOneLines(in, out);
  RobotLines(in, out);
  ViewTable(in, out);
  ViewAteLines(in, out);
  MatchLines(in, out);
  DataLines(in, out);
  if (!in.mission.keyframes) {
    for (const auto& r : in.mission.robots) out += SessionStatsLine(r->id(), r->session.stats());
  }
  return out;
}

std::string MarkdownRow(const ReportInput& in) {
  const Evaluation& ev = in.evaluation;
  const ViewAte& v1 = ev.view_ate.front();
  std::size_t merged = 1;
  for (const ViewEvaluation& v : ev.views) merged += v.viewer == 1 && v.merged ? 1 : 0;
  char ate[32] = "n/a";
  if (v1.ate.ok()) std::snprintf(ate, sizeof ate, "%.3f", v1.ate.ate.rmse);
  std::string out;
  Add(out, "| %s | %zu | %s | %zu / %zu | %s | %.3f | %llu / %llu | %llu |\n",
      in.options.run.c_str(), ev.robots.size(), in.options.mode_name.c_str(), merged,
      ev.robots.size(), ate, static_cast<double>(in.mission.accounting.Total()) / 1e6,
      static_cast<unsigned long long>(ev.matches.accepted - ev.matches.wrong),
      static_cast<unsigned long long>(ev.matches.accepted),
      static_cast<unsigned long long>(ev.matches.wrong));
  return out;
}

}  // namespace msgraphs::tools::collab
