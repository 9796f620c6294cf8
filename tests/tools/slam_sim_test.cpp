// SPDX-License-Identifier: MIT
// The local S-Graph end to end: the simulator records a robot (VLP-16 pcap, CAN candump), the
// real msgraphs_slam process maps it through the drivers, and this test checks its TUM output
// against the ground truth itself (truth interpolated at each keyframe's stamp, SE(3) Umeyama,
// RMSE; tools/ate.hpp), side by
// side with the encoder odometry at the same keyframes, and that walls and rooms were mapped.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "msgraphs/tools/ate.hpp"
#include "msgraphs/tools/tum.hpp"
#include "tool_process.hpp"

namespace msgraphs::test {
namespace {

std::size_t Lines(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  std::size_t n = 0;
  while (std::getline(in, line)) ++n;
  return n;
}

TEST(SlamSim, OneRobotMapsTheOfficeFarBetterThanItsEncoders) {
  const std::string run = Temp("slam_run"), out = Temp("slam_out");
  std::filesystem::remove_all(run);
  std::filesystem::remove_all(out);
  ASSERT_EQ(
      Wait(Spawn({MSGRAPHS_SIM_TOOL, "--world", MSGRAPHS_OFFICE_WORLD, "--out", run, "--robots",
                  "1", "--duration-s", "90", "--seed", "3", "--shared-rooms", "0"})),
      0);
  ASSERT_EQ(Wait(Spawn({MSGRAPHS_SLAM_TOOL, "--run", run, "--robot", "1", "--out", out})), 0);
  const auto truth = tools::ReadTum(run + "/robot1/ground_truth.tum");
  const auto slam = tools::ReadTum(out + "/keyframes.tum");
  const auto encoders = tools::ReadTum(out + "/odometry_keyframes.tum");
  ASSERT_GT(slam.size(), 40u);  // ~1 keyframe per metre
  ASSERT_EQ(slam.size(), encoders.size());
  const auto ate_slam = tools::ComputeAte(slam, truth),
             ate_encoders = tools::ComputeAte(encoders, truth);
  ASSERT_TRUE(ate_slam.ok && ate_encoders.ok);
  // The truth spans the whole recording: every keyframe is scored.
  EXPECT_EQ(ate_slam.pairs.paired, slam.size()) << ate_slam.pairs.DescribeUnpaired();
  std::printf("ATE over %zu keyframes: S-Graph %.3f m, encoder odometry %.3f m\n", slam.size(),
              ate_slam.rmse, ate_encoders.rmse);
  EXPECT_LT(ate_slam.rmse, 0.05);
  EXPECT_LT(ate_slam.rmse, ate_encoders.rmse / 4);
  EXPECT_GE(Lines(out + "/walls.csv"), 1u + 8u);  // header and at least eight planes
  EXPECT_GE(Lines(out + "/rooms.csv"), 1u + 1u);  // header and at least one room
  std::filesystem::remove_all(run);
  std::filesystem::remove_all(out);
}

}  // namespace
}  // namespace msgraphs::test
