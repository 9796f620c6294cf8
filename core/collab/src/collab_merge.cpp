// SPDX-License-Identifier: MIT
// The merge decision per peer (merge_rule.hpp): each map's walls and symmetries kept current,
// the hypotheses searched when either map, either free space or the room matches changed, the
// rule applied with the current merge as hysteresis, and every change of decision logged.
#include <algorithm>

#include "collab_session_impl.hpp"

namespace msgraphs::core {
namespace {

MergeEvidence Evidence(const Hypothesis& h) {
  MergeEvidence e;
  e.agreement_m = h.agreement.agreement_m;
  e.constraint_m = h.agreement.constraint_m;
  e.conflict_m = h.conflict_known ? h.conflict_m() : 0.0;
  e.votes = h.votes;
  e.sources = h.sources;
  return e;
}

// A map's symmetries: its alignment with itself, the strongest that constrain both directions.
void KeepSymmetries(const AlignmentSearch& search, double min_constraint_m, BoundedVector<Hypothesis>& out) {
  out.clear();
  for (const Hypothesis& h : search.hypotheses()) {
    if (out.full()) break;
    if (h.agreement.constraint_m >= min_constraint_m) out.push_back(h);
  }
}

}  // namespace

void CollabSession::Impl::RefreshOwnMap() {
  const DistilledGraph& g = own_graph;
  if (own_walls_version == g.version && own_symmetries_version == g.version) return;
  own_walls.Build(g.walls.span(), config.search.min_wall_length_m);
  own_walls_version = g.version;
  symmetry_search.Search(own_walls, g.rooms.span(), own_walls, g.rooms.span(), {}, true);
  KeepSymmetries(symmetry_search, config.merge.min_rival_constraint_m, own_symmetries);
  own_symmetries_version = g.version;
}

void CollabSession::Impl::RefreshPeerMap(Peer& p) {
  if (p.walls_version == p.graph.version && p.symmetries_version == p.graph.version) return;
  p.walls.Build(p.graph.walls.span(), config.search.min_wall_length_m);
  p.walls_version = p.graph.version;
  symmetry_search.Search(p.walls, p.graph.rooms.span(), p.walls, p.graph.rooms.span(), {}, true);
  KeepSymmetries(symmetry_search, config.merge.min_rival_constraint_m, p.symmetries);
  p.symmetries_version = p.graph.version;
}

void CollabSession::Impl::Log(const Peer& p, MergeEvent event) {
  MergeLogEntry& e = log[static_cast<std::size_t>(log_sequence % log.size())];
  if (log_sequence >= log.size()) ++stats.log_dropped;
  e = MergeLogEntry{};
  e.sequence = ++log_sequence;
  e.now_s = now_s;
  e.peer = p.robot;
  e.event = event;
  const MergeDecision& d = p.decision;
  e.verdict = d.verdict;
  if (d.has_leader || d.has_best_refuted) {
    const Hypothesis& h = d.has_leader ? d.leader : d.best_refuted;
    e.T_self_peer = h.T_a_b.ToIsometry(floor_z_m - PeerFloor(p));
    e.leader = Evidence(h);
  }
  e.has_rival = d.has_rival;
  if (d.has_rival) e.rival = Evidence(d.rival);
  e.rival_from_symmetry = d.rival_from_symmetry;
  e.symmetric = d.symmetric;
  e.hypotheses = d.hypotheses;
  e.refuted = d.refuted;
  e.set_aside = d.set_aside;
  e.places = d.places;
  ++stats.log_entries;
}

bool CollabSession::Impl::DecidePeer(Peer& p) {
  const std::uint32_t own_version = own_graph.version;
  if (p.decided_once && p.decided_own == own_version && p.decided_peer == p.graph.version &&
      p.decided_own_free == own_free_version && p.decided_free == p.free_version &&
      p.decided_matches == p.matches.size() && p.decided_places == p.places_version) {
    return false;
  }
  p.decided_once = true;
  p.decided_own = own_version;
  p.decided_peer = p.graph.version;
  p.decided_own_free = own_free_version;
  p.decided_free = p.free_version;
  p.decided_matches = p.matches.size();
  p.decided_places = p.places_version;
  ++stats.decisions;

  const MergeVerdict before = p.decision.verdict;
  MergeDecision d;
  if (!p.has_free || own_free.empty()) {
    d.verdict = MergeVerdict::kNoFreeSpace;
  } else {
    // Room matches propose their transforms too.
    seeds.clear();
    for (const RoomMatch& m : p.matches) {
      if (!seeds.try_push_back(PlanarTransform::FromIsometry(m.T_a_b))) break;
    }
    search.Search(own_walls, own_graph.rooms.span(), p.walls, p.graph.rooms.span(), seeds.span(), false);
    ++stats.searches;
    if (search.truncated()) ++stats.searches_truncated;
    MergeInputs in;
    in.walls_a = &own_walls;
    in.walls_b = &p.walls;
    in.free_a = &own_free;
    in.free_b = &p.free;
    in.hypotheses = search.hypotheses();
    in.truncated = search.truncated();
    in.sym_a = own_symmetries.span();
    in.sym_b = p.symmetries.span();
    in.channels = search.channels();
    d = DecideMerge(in, search, config.merge, p.merged ? &p.T_merge : nullptr);
    // Undecided between two transforms: the points of the places held may tell them apart.
    WeighPlaces(p, in, d);
  }
  const double same_m = config.search.same_distance_m, same_rad = config.search.same_angle_rad;
  // Confirmation: a new merge, or a move to another transform, needs the same leader to win
  // `confirmations` decisions with no other leader winning in between (decisions that merge
  // nothing, e.g. an exchange on which an artefact refuted it, do not reset the count); the
  // current merge refined on new walls needs none. A confirmation must come from a newer graph
  // (ours or the peer's): one exchange brings the peer's graph, its free space and its room
  // matches as separate messages, each a decision, and three wrong merges of the benchmark were
  // "confirmed" by the second decision of the exchange that proposed them. And the newer
  // graphs must have added evidence for it in its weakest direction: at least one conflict
  // stretch (min_stretch_m, the least that counts against a transform) more of wall laid on
  // wall across that direction (the constraint, WallAgreement::constraint_m). A newer graph
  // whose new walls all fall where the other robot has not looked, or only on its free
  // space's edges, tests nothing: in m014-multi-wing of the benchmark, two robots each in its
  // own copy of a wing agreed on the same 17.8 m of wall at 10 and 20 s, and the second
  // decision "confirmed" a transform 14 m off. Nor do new walls along the weakest direction: a
  // slide along it keeps them on wall. In the office demo, robot 3 took robot 1 six metres down
  // a corridor: its agreement grew from 29.5 to 114 m between 10 and 20 s, all of it corridor
  // wall, while the 11.6 m of cross wall that fixed the slide (two rooms' walls coinciding by
  // chance) stayed the same, and the true transform, the same corridor with nothing across,
  // stood beside it unrefuted.
  bool leader_replaced = false;
  if (d.verdict == MergeVerdict::kMerge && !d.keeping) {
    const bool newer = own_version != p.pending_own || p.graph.version != p.pending_peer;
    const double constraint_m = d.leader.agreement.constraint_m;
    if (p.pending_count > 0 && SameTransform(d.leader.T_a_b, p.pending_T, 2 * same_m, 2 * same_rad)) {
      if (newer && constraint_m >= p.pending_constraint_m + config.merge.conflict.min_stretch_m) {
        ++p.pending_count;
        p.pending_constraint_m = constraint_m;
      }
    } else {
      // Another leader than the one awaiting confirmation: logged even when the verdict stays
      // "awaits confirmation", so that a merge log shows why a leader was never confirmed.
      leader_replaced = p.pending_count > 0;
      p.pending_count = 1;
      p.pending_constraint_m = constraint_m;
    }
    p.pending_own = own_version;
    p.pending_peer = p.graph.version;
    p.pending_T = d.leader.T_a_b;
    if (p.pending_count < config.merge.confirmations) d.verdict = MergeVerdict::kUnconfirmed;
  }
  p.decision = d;

  // Apply it: merge, revise, keep, undo.
  bool changed = false;
  if (d.verdict == MergeVerdict::kMerge) {
    if (!p.merged) {
      p.merged = true;
      p.T_merge = d.leader.T_a_b;
      p.T_self_peer = p.T_merge.ToIsometry(floor_z_m - PeerFloor(p));
      ++p.stats.merges;
      ++stats.merges;
      if (p.stats.first_merge_s < 0) p.stats.first_merge_s = now_s;
      Log(p, MergeEvent::kMerged);
      changed = true;
    } else if (!SameTransform(d.leader.T_a_b, p.T_merge, same_m, same_rad)) {
      p.T_merge = d.leader.T_a_b;
      p.T_self_peer = p.T_merge.ToIsometry(floor_z_m - PeerFloor(p));
      ++p.stats.revised;
      ++stats.revised;
      Log(p, MergeEvent::kRevised);
      changed = true;
    } else {
      p.T_merge = d.leader.T_a_b;  // refined on the walls seen since
      if (before != d.verdict) Log(p, MergeEvent::kMerged);
    }
  } else if (p.merged && (d.verdict == MergeVerdict::kTruncated ||
                          (d.verdict == MergeVerdict::kAmbiguous && d.keeping && !d.overturned))) {
    // Kept: the search lost candidates (nothing new is known), or a rival stands that does not
    // beat the merge.
    if (before != d.verdict) Log(p, MergeEvent::kKept);
  } else if (p.merged) {
    p.merged = false;
    ++p.stats.undone;
    ++stats.undone;
    Log(p, MergeEvent::kUndone);
    changed = true;
  } else if (before != d.verdict || !p.logged || leader_replaced) {
    Log(p, MergeEvent::kUndecided);
  }
  p.logged = true;

  // What the peer's stats show of it.
  CollabPeerStats& s = p.stats;
  s.verdict = d.verdict;
  s.hypotheses = d.hypotheses;
  s.refuted = d.refuted;
  s.undecided = !p.merged && d.has_leader;
  s.symmetric = d.symmetric;
  s.rival_from_symmetry = d.rival_from_symmetry;
  s.leader = d.has_leader ? Evidence(d.leader) : MergeEvidence{};
  s.rival = d.has_rival ? Evidence(d.rival) : MergeEvidence{};
  s.set_aside = d.set_aside;
  s.places = d.places;
  // The room matches the merge agrees with.
  p.consistent_count = 0;
  if (p.merged) {
    for (std::uint32_t i = 0; i < p.matches.size(); ++i) {
      if (SameTransform(PlanarTransform::FromIsometry(p.matches[i].T_a_b), p.T_merge, config.anchored_translation_m,
                        config.anchored_rotation_rad)) {
        p.consistent[p.consistent_count++] = i;
      }
    }
  }
  return changed;
}

}  // namespace msgraphs::core
