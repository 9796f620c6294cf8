// SPDX-License-Identifier: MIT
#include "peer_stats_report.hpp"

#include <cstdio>

namespace msgraphs::tools::collab {

std::optional<core::CollabPeerStats> FindPeerStats(const core::CollabSession& session,
                                                   std::uint16_t robot) {
  for (std::size_t i = 0; i < session.peers(); ++i) {
    const core::CollabPeerStats p = session.peer_stats(i);
    if (p.robot == robot) return p;
  }
  return std::nullopt;
}

std::string PeerStatsLine(int viewer, const core::CollabPeerStats& p, std::size_t wrong) {
  char b[512];
  std::snprintf(b, sizeof b,
                "  view of robot %d: robot %u %s (%s); %zu hypotheses, %zu refuted; leader: walls agree "
                "%.1f m, %.1f m in its weakest direction, %.2f m conflict; rival %.1f m%s%s; "
                "%llu merges, %llu revised, %llu undone; %zu accepted room matches wrong\n",
                viewer, p.robot, p.merged ? "merged" : "NOT merged", core::ToString(p.verdict), p.hypotheses,
                p.refuted, p.leader.agreement_m, p.leader.constraint_m, p.leader.conflict_m, p.rival.agreement_m,
                p.rival_from_symmetry ? " (a symmetry)" : "", p.symmetric ? ", symmetric" : "",
                static_cast<unsigned long long>(p.merges), static_cast<unsigned long long>(p.revised),
                static_cast<unsigned long long>(p.undone), wrong);
  return b;
}

std::string SessionStatsLine(int robot, const core::CollabSessionStats& st) {
  char b[1280];
  std::snprintf(
      b, sizeof b,
      "robot %d session: %zu own rooms (peak room cloud %zu points), %zu peers, stores %.1f MB; "
      "refused: rooms %llu, clouds too large %llu, descriptors %llu, pending %llu, matches %llu; "
      "cache evictions %llu; solves %llu (%llu failed; factors %llu added, %llu kept, %llu removed); marginal wall covariances %llu times "
      "(%llu fell back; %llu solved without peers' priors, %llu of those failed); places: %llu asked, %llu received, %llu served, %llu refused, %llu "
      "unanswered, %llu unsolicited; %llu decisions weighed on them, %llu transforms set aside\n",
      robot, st.own_rooms, st.room_points_peak, st.peers, static_cast<double>(st.store_bytes) / 1e6,
      static_cast<unsigned long long>(st.rooms_refused),
      static_cast<unsigned long long>(st.room_clouds_too_large),
      static_cast<unsigned long long>(st.descriptors_refused),
      static_cast<unsigned long long>(st.pending_refused),
      static_cast<unsigned long long>(st.matches_refused),
      static_cast<unsigned long long>(st.cache_evictions),
      static_cast<unsigned long long>(st.solves),
      static_cast<unsigned long long>(st.solve_failures),
      static_cast<unsigned long long>(st.solve_factors_added),
      static_cast<unsigned long long>(st.solve_factors_kept),
      static_cast<unsigned long long>(st.solve_factors_removed),
      static_cast<unsigned long long>(st.marginal_updates),
      static_cast<unsigned long long>(st.marginal_failures),
      static_cast<unsigned long long>(st.own_evidence_jobs),
      static_cast<unsigned long long>(st.own_solve_failures),
      static_cast<unsigned long long>(st.place_requests_sent),
      static_cast<unsigned long long>(st.place_clouds_received),
      static_cast<unsigned long long>(st.place_requests_served),
      static_cast<unsigned long long>(st.place_requests_refused),
      static_cast<unsigned long long>(st.place_requests_unanswered),
      static_cast<unsigned long long>(st.place_clouds_unsolicited),
      static_cast<unsigned long long>(st.place_duels), static_cast<unsigned long long>(st.place_set_aside));
  return b;
}

void WritePeerStats(JsonWriter& json, const core::CollabPeerStats& p) {
  json.BeginObject();
  json.Field("merged", p.merged);
  json.Field("graph_version", p.graph_version);
  json.Field("walls", p.walls);
  json.Field("rooms", p.rooms);
  json.Field("descriptors", p.descriptors);
  json.Field("matches", p.matches);
  json.Field("consistent", p.consistent);
  json.Field("verdict", core::ToString(p.verdict));
  json.Field("hypotheses", p.hypotheses);
  json.Field("refuted", p.refuted);
  json.Field("undecided", p.undecided);
  json.Field("symmetric", p.symmetric);
  json.Field("rival_from_symmetry", p.rival_from_symmetry);
  json.Field("leader_agreement_m", p.leader.agreement_m);
  json.Field("leader_constraint_m", p.leader.constraint_m);
  json.Field("leader_conflict_m", p.leader.conflict_m);
  json.Field("rival_agreement_m", p.rival.agreement_m);
  json.Field("rival_constraint_m", p.rival.constraint_m);
  json.Field("rival_conflict_m", p.rival.conflict_m);
  json.Field("set_aside", p.set_aside);
  json.Field("places", p.places);
  json.Field("merges", p.merges);
  json.Field("revised", p.revised);
  json.Field("undone", p.undone);
  json.Field("first_merge_s", p.first_merge_s);
  json.Field("has_free_space", p.has_free_space);
  json.Field("malformed", p.malformed);
  json.Field("graph_gaps", p.graph_gaps);
  json.EndObject();
}

void WriteSessionStats(JsonWriter& json, const core::CollabSessionStats& st) {
  json.BeginObject();
  json.Field("own_rooms", st.own_rooms);
  json.Field("room_points_peak", st.room_points_peak);
  json.Field("peers", st.peers);
  json.Field("store_bytes", st.store_bytes);
  json.Field("rooms_refused", st.rooms_refused);
  json.Field("room_clouds_too_large", st.room_clouds_too_large);
  json.Field("descriptors_refused", st.descriptors_refused);
  json.Field("pending_refused", st.pending_refused);
  json.Field("matches_refused", st.matches_refused);
  json.Field("cache_evictions", st.cache_evictions);
  json.Field("solves", st.solves);
  json.Field("solve_failures", st.solve_failures);
  json.Field("solve_factors_added", st.solve_factors_added);
  json.Field("solve_factors_kept", st.solve_factors_kept);
  json.Field("solve_factors_removed", st.solve_factors_removed);
  json.Field("marginal_updates", st.marginal_updates);
  json.Field("marginal_failures", st.marginal_failures);
  json.Field("own_evidence_jobs", st.own_evidence_jobs);
  json.Field("own_solve_failures", st.own_solve_failures);
  json.Field("undecided_peers", st.undecided);
  json.Field("decisions", st.decisions);
  json.Field("merges", st.merges);
  json.Field("merges_revised", st.revised);
  json.Field("merges_undone", st.undone);
  json.Field("searches", st.searches);
  json.Field("searches_truncated", st.searches_truncated);
  json.Field("free_space_sent", st.free_space_sent);
  json.Field("solve_room_pairs", st.solve_room_pairs);
  json.Field("solve_wall_pairs", st.solve_wall_pairs);
  json.Field("solve_origin_measurements", st.solve_origin_measurements);
  json.Field("solve_room_wall_edges", st.solve_room_wall_edges);
  json.Field("solve_room_wall_refused", st.solve_room_wall_refused);
  json.Field("malformed", st.malformed);
  json.EndObject();
}

}  // namespace msgraphs::tools::collab
