// SPDX-License-Identifier: MIT
// The JSON summary (--summary FILE). Schema: docs/collab-summary.md; bump kSummaryVersion on any
// change a reader would notice (a renamed or removed key; new keys are compatible).
#include "json_writer.hpp"
#include "peer_stats_report.hpp"
#include "report.hpp"

namespace msgraphs::tools::collab {
namespace {

void WritePairs(JsonWriter& json, const PairCounts& pairs) {
  json.Field("paired", pairs.paired);
  json.Field("unpaired", pairs.unpaired_total());
  json.Key("unpaired_by_reason");
  json.BeginObject();
  for (std::size_t k = 0; k < kUnpairedReasons; ++k)
    json.Field(Key(static_cast<Unpaired>(k)), pairs.unpaired[k]);
  json.EndObject();
}

void WriteAte(JsonWriter& json, const AteResult& ate, bool ok, const std::string& error) {
  json.Field("ok", ok);
  if (ok)
    json.FieldNull("error");
  else
    json.Field("error", error);
  // Figures only when they stand: a failed ATE has no number a reader could average.
  for (const auto& [key, value] :
       {std::pair{"rmse_m", ate.rmse}, std::pair{"mean_m", ate.mean},
        std::pair{"median_m", ate.median}, std::pair{"max_m", ate.max}}) {
    if (ok)
      json.Field(key, value);
    else
      json.FieldNull(key);
  }
  WritePairs(json, ate.pairs);
}

void WriteOptions(JsonWriter& json, const Options& o) {
  json.Key("options");
  json.BeginObject();
  json.Field("mode", o.mode_name);
  json.Field("cloud", o.cloud_name);
  json.Field("cloud_step_m", static_cast<double>(o.session.cloud_step_m));
  json.Field("feedback", o.feedback);
  json.Field("places", o.session.places.budget_bytes_per_peer > 0);
  json.Field("exchange_every_s", o.every_s);
  json.Field("wrong_origin_m", o.evaluation.wrong_origin_m);
  json.Field("wrong_origin_deg", o.evaluation.wrong_origin_deg);
  json.Field("wrong_match_m", kWrongMatch_m);
  json.Field("wrong_match_rad", kWrongMatch_rad);
  json.Field("truth_gap_periods", PairingConfig{}.gap_periods);
  json.EndObject();
}

void WriteRobots(JsonWriter& json, const ReportInput& in) {
  json.Key("robots");
  json.BeginArray();
  for (const RobotEvaluation& r : in.evaluation.robots) {
    json.BeginObject();
    json.Field("robot", r.robot);
    json.Field("start_delay_s", r.start_delay_s);
    json.Field("start_delay_source", r.start_delay_source);
    json.Field("keyframes", r.keyframes.size());
    json.Key("truth");
    json.BeginObject();
    json.Field("samples", r.truth.samples().size());
    json.Field("median_period_s", r.truth.median_period_s());
    json.Field("gap_limit_s", r.truth.gap_limit_s());
    json.EndObject();
    json.Key("own_ate");
    json.BeginObject();
    WriteAte(json, r.own, r.own.ok, r.own.error);
    json.EndObject();
    if (!in.mission.keyframes) {
      json.Key("session");
      WriteSessionStats(json,
                        in.mission.robots[static_cast<std::size_t>(r.robot - 1)]->session.stats());
    }
    json.EndObject();
  }
  json.EndArray();
}

void WriteExplanation(JsonWriter& json, const ViewExplanation* e) {
  json.Key("explanation");
  if (e == nullptr) {
    json.Null();
    return;
  }
  json.BeginObject();
  json.Field("cause", e->cause);
  json.Field("checked", e->checked);
  json.Field("truth_proposed", e->proposed);
  json.Field("truth_rank", e->rank);
  json.Field("hypotheses", e->hypotheses);
  json.Field("truth_agreement_m", e->truth.agreement.agreement_m);
  json.Field("truth_constraint_m", e->truth.agreement.constraint_m);
  json.Field("truth_conflict_m", e->truth.conflict_m());
  json.Field("truth_walls_in_free_m", e->truth.conflict_b_in_a.walls_in_free_m + e->truth.conflict_a_in_b.walls_in_free_m);
  json.Field("truth_openings_on_walls_m",
             e->truth.conflict_b_in_a.openings_on_solid_m + e->truth.conflict_a_in_b.openings_on_solid_m);
  json.Field("rule_verdict", core::ToString(e->decision.verdict));
  json.Field("leader_truth_distance_m", e->leader_truth_distance_m);
  json.Field("rival_agreement_m", e->decision.has_rival ? e->decision.rival.agreement.agreement_m : 0.0);
  json.EndObject();
}

void WriteViews(JsonWriter& json, const Evaluation& ev, const std::vector<ViewExplanation>& explanations) {
  json.Key("views");
  json.BeginArray();
  for (const ViewEvaluation& v : ev.views) {
    const ViewExplanation* e = nullptr;
    for (const ViewExplanation& x : explanations) {
      if (x.viewer == v.viewer && x.robot == v.robot) e = &x;
    }
    json.BeginObject();
    WriteExplanation(json, e);
    json.Field("viewer", v.viewer);
    json.Field("robot", v.robot);
    json.Field("merged", v.merged);
    json.Field("first_merge_s", v.history.first_merge_s);
    json.Field("ever_merged", v.history.first_merge_s.has_value());
    json.Field("unmerged_later", v.history.unmerges() > 0);
    json.Field("unmerges", v.history.unmerges());
    json.Key("merge_changes");
    json.BeginArray();
    for (const MergeChange& c : v.history.changes) {
      json.BeginObject();
      json.Field("mission_time_s", c.mission_time_s);
      json.Field("merged", c.merged);
      json.EndObject();
    }
    json.EndArray();
    json.Key("origin_error");
    json.BeginObject();
    json.Field("checked", v.origin.checked);
    if (v.origin.checked) {
      json.FieldNull("reason");
      json.Field("translation_m", v.origin.translation_m);
      json.Field("xy_m", v.origin.xy_m);
      json.Field("z_m", v.origin.z_m);
      json.Field("rotation_deg", v.origin.rotation_deg);
    } else {
      json.Field("reason", v.origin.reason);
      for (const char* key : {"translation_m", "xy_m", "z_m", "rotation_deg"}) json.FieldNull(key);
    }
    json.EndObject();
    json.Field("verdict", Key(v.verdict));
    json.Field("first_wrong_s", v.first_wrong_s);
    json.Field("worst_origin_error_m", v.worst_origin.checked ? v.worst_origin.translation_m : 0.0);
    json.Field("worst_origin_error_deg", v.worst_origin.checked ? v.worst_origin.rotation_deg : 0.0);
    json.Field("factors", v.factors);
    json.Key("matches");
    json.BeginObject();
    json.Field("accepted", v.matches_accepted);
    json.Field("wrong", v.matches_wrong);
    json.Field("unchecked", v.matches_unchecked);
    json.EndObject();
    json.Key("peer_stats");
    if (v.peer_stats)
      WritePeerStats(json, *v.peer_stats);
    else
      json.Null();
    json.EndObject();
  }
  json.EndArray();
  const ViewTotals t = ev.totals();
  json.Key("view_totals");
  json.BeginObject();
  json.Field("views", t.views);
  json.Field("merged", t.merged);
  json.Field("right", t.right);
  json.Field("wrong", t.wrong);
  json.Field("unchecked", t.unchecked);
  json.Field("not_merged", t.not_merged);
  json.EndObject();
}

void WriteViewAte(JsonWriter& json, const Evaluation& ev) {
  json.Key("view_ate");
  json.BeginArray();
  for (const ViewAte& v : ev.view_ate) {
    json.BeginObject();
    json.Field("viewer", v.viewer);
    WriteAte(json, v.ate.ate, v.ate.ok(), v.ate.failure());
    json.Key("members");
    json.BeginArray();
    for (const AggregatedMember& m : v.ate.members) {
      json.BeginObject();
      json.Field("robot", m.robot);
      WritePairs(json, m.pairs);
      json.EndObject();
    }
    json.EndArray();
    json.Key("missing");
    json.BeginArray();
    for (const AggregatedMissing& m : v.ate.missing) {
      json.BeginObject();
      json.Field("robot", m.robot);
      json.Field("merged", m.merged);
      json.Field("reason", m.reason);
      json.EndObject();
    }
    json.EndArray();
    json.EndObject();
  }
  json.EndArray();
}

void WriteMatchesAndData(JsonWriter& json, const ReportInput& in) {
  const MatchStatistics& m = in.evaluation.matches;
  json.Key("matches");
  json.BeginObject();
  json.Field("proposed", m.proposed);
  json.Field("rejected_fine", m.rejected_fine);
  json.Field("checked_anchored", m.checked_anchored);
  json.Field("rejected_anchored", m.rejected_anchored);
  json.Field("rejected_consistency", m.rejected_consistency);
  json.Field("accepted", m.accepted);
  json.Field("wrong", m.wrong);
  json.Field("unchecked", m.unchecked);
  json.EndObject();
  const Accounting& acc = in.mission.accounting;
  json.Key("data");
  json.BeginObject();
  json.Field("total_bytes", acc.Total());
  json.Field("malformed_messages", acc.malformed);
  json.Key("bytes_by_type");
  json.BeginObject();
  for (int t = 0; t < kMessageTypes; ++t) json.Field(MessageTypeKey(t), acc.Total(t));
  json.EndObject();
  json.Key("links");
  json.BeginArray();
  for (const auto& from : in.mission.robots) {
    for (const auto& to : in.mission.robots) {
      if (from == to) continue;
      json.BeginObject();
      json.Field("from", int{from->id()});
      json.Field("to", int{to->id()});
      json.Field("bytes", acc.Link(from->index, to->index));
      json.EndObject();
    }
  }
  json.EndArray();
  json.EndObject();
}

}  // namespace

std::string JsonSummary(const ReportInput& in) {
  JsonWriter json;
  json.BeginObject();
  json.Field("schema", "msgraphs_collab_summary");
  json.Field("schema_version", kSummaryVersion);
  json.Field("run", in.options.run);
  WriteOptions(json, in.options);
  json.Field("run_time_s", in.run.run_time_s);
  json.Field("mission_time_s", in.run.mission_time_s);
  json.Field("exchanges", in.run.exchanges.size());
  WriteRobots(json, in);
  WriteViews(json, in.evaluation, in.explanations);
  WriteViewAte(json, in.evaluation);
  WriteMatchesAndData(json, in);
  json.EndObject();
  return json.text();
}

}  // namespace msgraphs::tools::collab
