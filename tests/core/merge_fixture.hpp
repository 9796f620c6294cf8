// SPDX-License-Identifier: MIT
// A robot of the merge-decision tests (plan_building.hpp): what it shares of a planned building
// it saw (distilled walls, free-space summary, its own symmetries), and the merge rule's
// decision of one such robot about another (MERGE_DEBUG=1 prints it).
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <span>
#include <vector>

#include "msgraphs/core/collab/alignment_search.hpp"
#include "msgraphs/core/collab/merge_rule.hpp"
#include "plan_building.hpp"

namespace msgraphs::test {

using core::AlignmentSearch;
using core::DistilledGraph;
using core::FreeSpaceSummary;
using core::FreeSpaceSummaryConfig;
using core::Hypothesis;
using core::MergeDecision;
using core::MergeInputs;
using core::MergeRuleConfig;
using core::PlanarTransform;
using core::WallIndex;

struct Robot {
  Eigen::Isometry2d T_map_world;
  DistilledGraph graph;
  WallIndex walls;
  FreeSpaceSummary free;
  AlignmentSearch self;  // its symmetries

  Robot(const PlanBuilding& b, const std::vector<Seen>& seen, const Eigen::Isometry2d& T) : T_map_world(T) {
    graph = b.Walls(seen, T);
    EXPECT_TRUE(walls.Init(256));
    walls.Build(graph.walls.span(), 0.5);
    FreeSpaceSummaryConfig fc;
    fc.max_cells = 1 << 19;
    EXPECT_TRUE(free.Init(fc));
    b.Summary(seen, T, free);
    EXPECT_TRUE(self.Init({}));
    self.Search(walls, {}, walls, {}, {}, true);
  }
};

// What robot a's merge rule looks at about robot b, after `search` searched them.
inline MergeInputs InputsOf(Robot& a, Robot& b, AlignmentSearch& search) {
  MergeInputs in;
  in.walls_a = &a.walls;
  in.walls_b = &b.walls;
  in.free_a = &a.free;
  in.free_b = &b.free;
  in.hypotheses = search.hypotheses();
  in.truncated = search.truncated();
  in.sym_a = a.self.hypotheses();
  in.sym_b = b.self.hypotheses();
  in.channels = search.channels();
  return in;
}

// What robot a decides about robot b.
inline MergeDecision Decide(Robot& a, Robot& b, AlignmentSearch& search, const PlanarTransform* current = nullptr,
                            const MergeRuleConfig& config = {}, std::span<const PlanarTransform> set_aside = {}) {
  search.Search(a.walls, {}, b.walls, {}, {}, false);
  MergeInputs in = InputsOf(a, b, search);
  in.set_aside = set_aside;
  const MergeDecision d = DecideMerge(in, search, config, current);
  if (std::getenv("MERGE_DEBUG") != nullptr) {
    const auto show = [](const char* what, const Hypothesis& h) {
      std::printf("  %s: yaw %.3f t (%.2f %.2f) agreement %.2f constraint %.2f conflict b>a %.2f+%.2f a>b %.2f+%.2f votes %u src %u\n",
                  what, h.T_a_b.yaw_rad, h.T_a_b.t_m.x(), h.T_a_b.t_m.y(), h.agreement.agreement_m,
                  h.agreement.constraint_m, h.conflict_b_in_a.walls_in_free_m, h.conflict_b_in_a.openings_on_solid_m,
                  h.conflict_a_in_b.walls_in_free_m, h.conflict_a_in_b.openings_on_solid_m, h.votes, h.sources);
    };
    std::printf("verdict %s, %zu hypotheses, %zu refuted, symmetric %d, corners %zu/%zu clusters %zu kept %zu\n", core::ToString(d.verdict),
                d.hypotheses, d.refuted, d.symmetric, search.stats().corners_a, search.stats().corners_b,
                search.stats().clusters, search.stats().kept);
    if (d.has_leader) show("leader", d.leader);
    if (d.has_rival) show(d.rival_from_symmetry ? "rival (symmetry)" : "rival", d.rival);
    for (std::size_t i = 0; i < std::min<std::size_t>(6, search.hypotheses().size()); ++i) show("h", search.hypotheses()[i]);
  }
  return d;
}

inline PlanarTransform Truth(const Robot& a, const Robot& b) {
  const Eigen::Isometry2d T = a.T_map_world * b.T_map_world.inverse();
  return {std::atan2(T.linear()(1, 0), T.linear()(0, 0)), T.translation()};
}

}  // namespace msgraphs::test
