// SPDX-License-Identifier: MIT
// The full merge on the demo's mission (scripts/run_fleet.sh: three robots in the shipped office
// world for 180 s, seed 1, Spot's gait, symmetric rooms included): the simulator records it,
// msgraphs_collab runs every local S-Graph, distils and exchanges through the wire encodings,
// matches rooms with fine alignment and the consistency check, and solves each robot's
// collaborative graph. Checked here: every view (A's estimate of B, all six) is merged and right
// at the end and was never wrong on the way, in the text and the JSON summary; no accepted room
// match is wrong against the truth; robot 2's keyframes land on the ground truth in robot 1's
// frame. Until the merge confirmation asked for new evidence across the leader's weakest
// direction, robot 3 took robot 1 six metres down a corridor at 20 s of this very mission.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>

#include "msgraphs/tools/ate.hpp"
#include "msgraphs/tools/truth_pairing.hpp"
#include "msgraphs/tools/tum.hpp"
#include "tool_process.hpp"

namespace msgraphs::test {
namespace {

TEST(CollabSim, TheDemoMissionMergesEveryViewAndNeverWrongly) {
  const std::string run = Temp("collab_run"), out = Temp("collab_out"), log = Temp("collab_log");
  std::filesystem::remove_all(run);
  std::filesystem::remove_all(out);
  ASSERT_EQ(
      Wait(Spawn({MSGRAPHS_SIM_TOOL, "--world", MSGRAPHS_OFFICE_WORLD, "--out", run, "--robots",
                  "3", "--duration-s", "180", "--seed", "1"})),
      0);
  ASSERT_EQ(Wait(Spawn({"/bin/sh", "-c",
                        std::string(MSGRAPHS_COLLAB_TOOL) + " --run " + run + " --out " + out +
                            " --summary " + out + "/summary.json > " + log})),
            0);
  std::ifstream in(log);
  std::stringstream text;
  text << in.rdbuf();
  std::printf("%s", text.str().c_str());
  EXPECT_NE(text.str().find("robot 1 merged 3 of 3 robots"), std::string::npos);
  EXPECT_NE(text.str().find(" 0 of them wrong against the truth"), std::string::npos);
  // Every view, not only robot 1's: all merged, all origins right, in the text and the summary.
  EXPECT_NE(text.str().find("views: 6 of 6 merged; 6 right, 0 wrong, 0 unchecked, 0 not merged"),
            std::string::npos);
  // And never wrong on the way: a wrong merge undone an exchange later is still a wrong merge.
  EXPECT_EQ(text.str().find("(wrong from "), std::string::npos);
  std::ifstream summary_file(out + "/summary.json");
  std::stringstream summary;
  summary << summary_file.rdbuf();
  EXPECT_NE(summary.str().find("\"schema\": \"msgraphs_collab_summary\""), std::string::npos);
  std::size_t right = 0;
  for (std::size_t at = 0;
       (at = summary.str().find("\"verdict\": \"right\"", at)) != std::string::npos; ++at)
    ++right;
  EXPECT_EQ(right, 6u);
  EXPECT_GT(tools::ReadTum(out + "/robot1_in_robot2.tum").size(), 50u);
  // Robot 2's keyframes in robot 1's frame, against robot 2's truth in the world: the same rigid
  // alignment that puts robot 1 on its truth must put robot 2 on its own.
  const auto truth1 = tools::ReadTum(run + "/robot1/ground_truth.tum");
  const auto truth2 = tools::ReadTum(run + "/robot2/ground_truth.tum");
  const auto est1 = tools::ReadTum(out + "/robot1_in_robot1.tum");
  const auto est2 = tools::ReadTum(out + "/robot2_in_robot1.tum");
  ASSERT_GT(est2.size(), 50u);
  const auto ate1 = tools::ComputeAte(est1, truth1);
  ASSERT_TRUE(ate1.ok);
  EXPECT_EQ(ate1.pairs.paired, est1.size()) << ate1.pairs.DescribeUnpaired();
  const tools::PairedPoses paired2 = tools::PairWithTruth(est2, tools::TruthTrajectory(truth2));
  EXPECT_EQ(paired2.counts.paired, est2.size()) << paired2.counts.DescribeUnpaired();
  double sum2_xy = 0, sum2_z = 0;
  const std::size_t n = paired2.estimate.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d e = ate1.T_truth_estimate * paired2.estimate[i].T.translation() -
                              paired2.truth[i].T.translation();
    sum2_xy += e.head<2>().squaredNorm();
    sum2_z += e.z() * e.z();
  }
  ASSERT_GT(n, 50u);
  const double rmse2_xy = std::sqrt(sum2_xy / static_cast<double>(n));
  const double rmse2_z = std::sqrt(sum2_z / static_cast<double>(n));
  std::printf("robot 1 ATE %.3f m; robot 2 through robot 1's alignment %.3f m across, %.3f m in height\n",
              ate1.rmse, rmse2_xy, rmse2_z);
  // Across (what the merge decides): robot 2's own map is off by a few cm (docs/s-graph.md); a
  // wrong merge would put it metres away. In height, the peer's origin is placed through the two floors and is off by up to
  // 17 cm with Spot's gait in the recording (a known defect: docs/multi-robot.md), still far
  // from a wrong merge's metres.
  EXPECT_LT(rmse2_xy, 0.15);
  EXPECT_LT(rmse2_z, 0.3);
  std::filesystem::remove_all(run);
  std::filesystem::remove_all(out);
  std::filesystem::remove(log);
}


// Feedback is its own switch, not a side effect of the mode (issue 19's confounded ablation):
// in the rooms-only mode the merge's matched walls still reach each robot's own S-Graph as
// priors (they were collected only in the walls modes, so "Rooms" silently ran without
// feedback), and --feedback off leaves every own map without them.
std::size_t PriorsOfRobot(const std::string& text, int robot) {
  constexpr auto kAbsent = static_cast<std::size_t>(-1);
  const std::size_t line = text.find("wall priors from peers in each local S-Graph");
  if (line == std::string::npos) return kAbsent;
  const std::string entry = " robot " + std::to_string(robot) + " ";
  const std::size_t at = text.find(entry, line);
  if (at == std::string::npos || at > text.find('\n', line)) return kAbsent;
  return static_cast<std::size_t>(std::stoul(text.substr(at + entry.size())));
}

TEST(CollabSim, TheRoomsModeFeedsMatchedWallsBackAndFeedbackOffFeedsNone) {
  const std::string run = Temp("feedback_run"), log = Temp("feedback_log");
  std::filesystem::remove_all(run);
  ASSERT_EQ(
      Wait(Spawn({MSGRAPHS_SIM_TOOL, "--world", MSGRAPHS_OFFICE_WORLD, "--out", run, "--robots",
                  "2", "--duration-s", "150", "--seed", "1"})),
      0);
  auto collab = [&](const std::string& feedback) {
    EXPECT_EQ(Wait(Spawn({"/bin/sh", "-c",
                          std::string(MSGRAPHS_COLLAB_TOOL) + " --run " + run +
                              " --mode rooms --feedback " + feedback + " > " + log})),
              0);
    std::ifstream in(log);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
  };
  const std::string on = collab("on");
  ASSERT_NE(on.find("robot 1 merged 2 of 2 robots"), std::string::npos) << on;
  constexpr auto kAbsent = static_cast<std::size_t>(-1);
  ASSERT_NE(PriorsOfRobot(on, 1), kAbsent) << on;
  ASSERT_NE(PriorsOfRobot(on, 2), kAbsent) << on;
  EXPECT_GT(PriorsOfRobot(on, 1), 0u) << on;
  EXPECT_GT(PriorsOfRobot(on, 2), 0u) << on;
  const std::string off = collab("off");
  ASSERT_NE(off.find("robot 1 merged 2 of 2 robots"), std::string::npos) << off;
  ASSERT_NE(PriorsOfRobot(off, 1), kAbsent) << off;
  EXPECT_EQ(PriorsOfRobot(off, 1), 0u) << off;
  EXPECT_EQ(PriorsOfRobot(off, 2), 0u) << off;
  std::filesystem::remove_all(run);
  std::filesystem::remove(log);
}

// The fleet evaluation's knobs (issue 19): each robot's graph bounded by --max-keyframes (a
// value the graph refuses is an error, not a silent default), and --timing's per-robot tables.
TEST(CollabSim, ABoundedGraphAndItsTimingAreReported) {
  const std::string run = Temp("bounded_run"), log = Temp("bounded_log");
  std::filesystem::remove_all(run);
  ASSERT_EQ(
      Wait(Spawn({MSGRAPHS_SIM_TOOL, "--world", MSGRAPHS_OFFICE_WORLD, "--out", run, "--robots",
                  "2", "--duration-s", "40", "--seed", "2", "--shared-rooms", "0"})),
      0);
  auto collab = [&](const std::string& options) {
    const int status = Wait(Spawn({"/bin/sh", "-c",
                                   std::string(MSGRAPHS_COLLAB_TOOL) + " --run " + run + " " +
                                       options + " > " + log + " 2>&1"}));
    std::ifstream in(log);
    std::stringstream text;
    text << in.rdbuf();
    return std::pair{status, text.str()};
  };
  const auto [status, text] = collab("--max-keyframes 32 --timing");
  ASSERT_EQ(status, 0) << text;
  for (const char* robot : {"robot 1 timing: ", "robot 2 timing: "}) {
    const std::size_t at = text.find(robot);
    ASSERT_NE(at, std::string::npos) << text;
    std::size_t mapped = 0, in_graph = 0, peak = 0, sparsified = 0;
    ASSERT_EQ(std::sscanf(text.c_str() + at + std::string(robot).size(),
                          "%zu keyframes mapped, %zu in the graph (peak %zu, %zu sparsified)",
                          &mapped, &in_graph, &peak, &sparsified),
              4)
        << text.substr(at, 120);
    EXPECT_GT(mapped, 32u) << robot;  // more than the store holds: it was sparsified to it
    EXPECT_EQ(in_graph, 32u) << robot;
    EXPECT_EQ(peak, 32u) << robot;
    EXPECT_EQ(sparsified, mapped - 32) << robot;
  }
  EXPECT_NE(text.find("per keyframe total by map size [ms]"), std::string::npos);
  EXPECT_NE(text.find("resident set at the end: "), std::string::npos);
  const auto [refused, why] = collab("--max-keyframes 20");  // not above the local window (20)
  EXPECT_EQ(refused, 1) << why;
  EXPECT_NE(why.find("collab: "), std::string::npos) << why;
  std::filesystem::remove_all(run);
  std::filesystem::remove(log);
}

}  // namespace
}  // namespace msgraphs::test
