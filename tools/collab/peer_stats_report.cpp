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
  if (p.hypotheses < 2 && p.merged && wrong == 0) return "";
  char b[320];
  std::snprintf(b, sizeof b,
                "  view of robot %d: robot %u %s, %zu hypotheses%s (%zu matches, walls agree "
                "%.1f m; best rival %zu matches, %.1f m); %zu accepted matches wrong\n",
                viewer, p.robot, p.merged ? "merged" : "NOT merged", p.hypotheses,
                p.undecided ? ", undecided" : "", p.hypothesis_matches[0], p.agreement_m[0],
                p.hypothesis_matches[1], p.agreement_m[1], wrong);
  return b;
}

std::string SessionStatsLine(int robot, const core::CollabSessionStats& st) {
  char b[640];
  std::snprintf(
      b, sizeof b,
      "robot %d session: %zu own rooms (peak room cloud %zu points), %zu peers, stores %.1f MB; "
      "refused: rooms %llu, clouds too large %llu, descriptors %llu, pending %llu, matches %llu; "
      "cache evictions %llu; solves %llu (%llu failed); marginal wall covariances %llu times "
      "(%llu fell back)\n",
      robot, st.own_rooms, st.room_points_peak, st.peers, static_cast<double>(st.store_bytes) / 1e6,
      static_cast<unsigned long long>(st.rooms_refused),
      static_cast<unsigned long long>(st.room_clouds_too_large),
      static_cast<unsigned long long>(st.descriptors_refused),
      static_cast<unsigned long long>(st.pending_refused),
      static_cast<unsigned long long>(st.matches_refused),
      static_cast<unsigned long long>(st.cache_evictions),
      static_cast<unsigned long long>(st.solves),
      static_cast<unsigned long long>(st.solve_failures),
      static_cast<unsigned long long>(st.marginal_updates),
      static_cast<unsigned long long>(st.marginal_failures));
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
  json.Field("hypotheses", p.hypotheses);
  json.Field("undecided", p.undecided);
  json.Field("chosen_hypothesis_matches", p.hypothesis_matches[0]);
  json.Field("chosen_hypothesis_walls_agree_m", p.agreement_m[0]);
  json.Field("best_rival_matches", p.hypothesis_matches[1]);
  json.Field("best_rival_walls_agree_m", p.agreement_m[1]);
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
  json.Field("marginal_updates", st.marginal_updates);
  json.Field("marginal_failures", st.marginal_failures);
  json.Field("undecided_peers", st.undecided);
  json.Field("malformed", st.malformed);
  json.EndObject();
}

}  // namespace msgraphs::tools::collab
