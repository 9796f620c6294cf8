// SPDX-License-Identifier: MIT
#include "msgraphs/core/collab/place_decision.hpp"

#include <array>
#include <cmath>

namespace msgraphs::core {
namespace {

constexpr int kRounds = 4;
constexpr std::size_t kMaxCandidates = 8;

bool Undecided(const MergeDecision& d) {
  if (d.keeping) return false;
  // A one-direction rival (a channel probed along its line) stands for every slide along it:
  // points at one slide say nothing of the others.
  if (d.verdict == MergeVerdict::kAmbiguous) return !d.rival_one_direction;
  return d.verdict == MergeVerdict::kContradicted;
}

}  // namespace

PlaceDecision DecideWithPlaces(MergeInputs& in, const AlignmentSearch& search, const MergeRuleConfig& c,
                               const MergeDecision& first_decision, std::span<const PlaceView> places,
                               double cell_m, PlaceScorer& scorer, BoundedVector<PlanarTransform>& set_aside) {
  PlaceDecision out;
  out.decision = first_decision;
  set_aside.clear();
  // The least the wall-level test counts (a stretch of min_stretch_m), in summary cells.
  const auto min_cells = static_cast<std::size_t>(std::ceil(c.conflict.min_stretch_m / cell_m - 1e-9));
  const double same_m = search.config().same_distance_m, same_rad = search.config().same_angle_rad;
  for (int round = 0; round < kRounds && Undecided(out.decision); ++round) {
    const MergeDecision& d = out.decision;
    const Hypothesis& blocker = d.verdict == MergeVerdict::kAmbiguous ? d.rival : d.best_refuted;
    out.wants_place = true;
    out.first = d.leader.T_a_b;
    out.second = blocker.T_a_b;
    if (places.empty() || set_aside.full()) break;
    // The candidates: the leader, its blocker, and the standing hypotheses that could block.
    std::array<PlanarTransform, kMaxCandidates> candidates;
    std::size_t n = 0;
    auto add = [&](const PlanarTransform& T) {
      if (n == kMaxCandidates) return;
      for (std::size_t i = 0; i < n; ++i) {
        if (SameTransform(candidates[i], T, same_m, same_rad)) return;
      }
      for (const PlanarTransform& s : set_aside) {
        if (SameTransform(s, T, same_m, same_rad)) return;
      }
      candidates[n++] = T;
    };
    add(d.leader.T_a_b);
    add(blocker.T_a_b);
    for (Hypothesis& h : in.hypotheses) {
      if (h.agreement.agreement_m * c.symmetric_margin_ratio + c.margin_m <= d.leader.agreement.agreement_m) break;
      if (h.agreement.constraint_m < c.min_rival_constraint_m) continue;
      MeasureConflict(h, in, c.conflict);
      if (h.conflict_m() <= c.RefuteLimit(h)) add(h.T_a_b);
    }
    std::array<PlaceTally, kMaxCandidates> tallies{};
    for (std::size_t i = 0; i < n; ++i) {
      for (const PlaceView& p : places) {
        tallies[i] += scorer.Score(p.points, p.centre_m, candidates[i], *in.free_a, c.conflict.clearance_m);
      }
    }
    ++out.duels;
    std::size_t champion = 0;
    const auto net = [&](std::size_t i) {
      return static_cast<double>(tallies[i].explained) - static_cast<double>(tallies[i].contradicted);
    };
    for (std::size_t i = 1; i < n; ++i) {
      if (net(i) > net(champion)) champion = i;
    }
    std::size_t beaten = 0;
    for (std::size_t i = 0; i < n && !set_aside.full(); ++i) {
      if (i == champion || Duel(tallies[champion], tallies[i], c.margin_ratio, min_cells) != DuelOutcome::kFirstWins)
        continue;
      set_aside.push_back(candidates[i]);
      ++beaten;
    }
    if (beaten == 0) break;  // the places held cannot tell them apart: ask for another
    out.wants_place = false;
    in.set_aside = set_aside.span();
    out.decision = DecideMerge(in, search, c, nullptr);
  }
  if (Undecided(out.decision) && !out.wants_place) {
    const MergeDecision& d = out.decision;
    out.wants_place = true;
    out.first = d.leader.T_a_b;
    out.second = (d.verdict == MergeVerdict::kAmbiguous ? d.rival : d.best_refuted).T_a_b;
  }
  out.decision.set_aside = set_aside.size();
  out.decision.places = out.duels > 0 ? places.size() : 0;
  return out;
}

}  // namespace msgraphs::core
