// SPDX-License-Identifier: MIT
// msgraphs_fleet_ate as a process on hand-made node outputs: every robot is listed, and a robot
// whose keyframes have no truth is reported with the reason and fails the run instead of
// silently leaving the aggregated ATE.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "analytic_trajectory.hpp"
#include "msgraphs/tools/tum.hpp"
#include "tool_process.hpp"

namespace msgraphs::test {
namespace {

namespace fs = std::filesystem;

Eigen::Isometry3d Map(double yaw, double x, double y) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() << x, y, 0;
  return T;
}

struct Fleet {
  std::string run = Temp("fleet_ate_run"), out = Temp("fleet_ate_out"), log = Temp("fleet_log");
  // Each robot's map frame in the world, and its truth at 50 Hz over [0, truth_end_s].
  void Write(int robot,
             const Eigen::Isometry3d& T_world_map,
             double truth_end_s,
             const Eigen::Isometry3d& T_1_robot) {
    const fs::path gt = fs::path(run) / ("robot" + std::to_string(robot));
    const fs::path node = fs::path(out) / ("robot" + std::to_string(robot));
    fs::create_directories(gt);
    fs::create_directories(node);
    ASSERT_TRUE(
        tools::WriteTum((gt / "ground_truth.tum").string(), SampleTruth(50, 0, truth_end_s)));
    std::vector<tools::StampedPose> keyframes;  // 10 Hz scan-end stamps between truth samples
    for (double s = 1.037; s < 29; s += 0.5)
      keyframes.push_back({kT0 + s, T_world_map.inverse() * AnalyticPose(kT0 + s)});
    ASSERT_TRUE(tools::WriteTum((node / "keyframes.tum").string(), keyframes));
    // Robot 1's origins.csv: where it placed robot 2 (the truth); robot 2's: nothing merged.
    std::ofstream origins(node / "origins.csv");
    origins << "robot,merged,x,y,z,qx,qy,qz,qw\n";
    if (robot == 1) {
      const Eigen::Quaterniond q(T_1_robot.linear());
      origins << "2,1," << T_1_robot.translation().x() << ',' << T_1_robot.translation().y() << ','
              << T_1_robot.translation().z() << ',' << q.x() << ',' << q.y() << ',' << q.z() << ','
              << q.w() << '\n';
    }
  }
  int Run(std::string& text) {
    const int code = Wait(Spawn(
        {"/bin/sh", "-c",
         std::string(MSGRAPHS_FLEET_ATE_TOOL) + " --run " + run + " --out " + out + " > " + log}));
    std::ifstream in(log);
    std::stringstream s;
    s << in.rdbuf();
    text = s.str();
    std::printf("%s", text.c_str());
    return code;
  }
  ~Fleet() {
    fs::remove_all(run);
    fs::remove_all(out);
    fs::remove(log);
  }
};

TEST(FleetAte, EveryRobotIsScoredAgainstInterpolatedTruth) {
  Fleet f;
  const Eigen::Isometry3d T_w_1 = Map(0.3, 2, 1), T_w_2 = Map(-1.2, -4, 3);
  f.Write(1, T_w_1, 30, T_w_1.inverse() * T_w_2);
  f.Write(2, T_w_2, 30, {});
  std::string text;
  EXPECT_EQ(f.Run(text), 0);
  // 50 Hz truth, keyframes 3 ms off every sample: all 56 keyframes of each robot are paired.
  EXPECT_NE(text.find("robot 1 alone: ATE 0.000 m over 56 keyframes (unpaired: none)"),
            std::string::npos);
  EXPECT_NE(text.find("robot 2 alone: ATE 0.000 m over 56 keyframes (unpaired: none)"),
            std::string::npos);
  EXPECT_NE(text.find("view of robot 1: merged 2 of 2 robots; aggregated ATE 0.000 m over 112"),
            std::string::npos);
  EXPECT_NE(text.find("origin of robot 2 off by 0.000 m, 0.00 deg"), std::string::npos);
  EXPECT_NE(text.find("view of robot 2: merged 1 of 2 robots; aggregated ATE 0.000 m over 56 "
                      "keyframes (robot 2 56 keyframes; missing: robot 1 (not merged))"),
            std::string::npos);
}

TEST(FleetAte, ARobotWithoutTruthAtItsKeyframesIsReportedAndFails) {
  Fleet f;
  const Eigen::Isometry3d T_w_1 = Map(0.3, 2, 1), T_w_2 = Map(-1.2, -4, 3);
  f.Write(1, T_w_1, 30, T_w_1.inverse() * T_w_2);
  f.Write(2, T_w_2, 0.5, {});  // robot 2's truth ends before its first keyframe
  std::string text;
  EXPECT_EQ(f.Run(text), 1);
  EXPECT_NE(text.find("robot 2 alone: ATE FAILED: fewer than 3 poses paired with the truth; 0 of "
                      "56 keyframes paired (unpaired: 56 after the truth)"),
            std::string::npos);
  EXPECT_NE(text.find("view of robot 1: merged 2 of 2 robots; aggregated ATE FAILED: robot 2 "
                      "merged but has 0 of 56 keyframes paired with its truth"),
            std::string::npos);
  EXPECT_NE(text.find("origin of robot 2 not checked (no truth alignment of robot 2)"),
            std::string::npos);
}

}  // namespace
}  // namespace msgraphs::test
