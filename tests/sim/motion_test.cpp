// SPDX-License-Identifier: MIT
// Spot's motion in the simulator: the gait (height bob, roll and pitch at the step rate, smooth,
// none when standing), encoder slip events exactly where mission.txt says, and ground truth
// written at any rate with the right spacing.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <vector>

#include "clocks.hpp"
#include "mission.hpp"
#include "mission_report.hpp"
#include "msgraphs/drivers/can_odometry/candump_file.hpp"
#include "msgraphs/drivers/can_odometry/odometry_stream.hpp"
#include "odometry_sim.hpp"
#include "scene.hpp"
#include "trajectory.hpp"
#include "truth.hpp"
#include "world.hpp"

namespace msgraphs::sim {
namespace {

namespace fs = std::filesystem;
constexpr double kDeg = std::numbers::pi / 180.0;

struct TempDir {
  fs::path path;
  explicit TempDir(const std::string& name)
      : path(fs::temp_directory_path() / ("msgraphs_" + name + "_" + std::to_string(getpid()))) {
    fs::create_directories(path);
  }
  ~TempDir() { fs::remove_all(path); }
};

// Stands 2 s, walks 10 s at 0.3 m/s and 10 s at 1 m/s (accelerating at 0.5 m/s^2), stops and
// stands 4 s.
Trajectory WalkingTrajectory(const GaitParams& gait) {
  Trajectory t(0.01, 0.5);
  PlanarPose p;
  double v = 0;
  auto run = [&](double seconds, double speed) {
    for (int i = 0; i < static_cast<int>(std::lround(seconds / 0.01)); ++i) {
      v += std::clamp(speed - v, -0.005, 0.005);
      p.x += v * 0.01;
      t.Append(p);
    }
  };
  t.Append(p);
  run(2, 0);
  run(10, 0.3);
  run(10, 1.0);
  run(4, 0);
  t.SetGait(gait);
  return t;
}

GaitParams FixedGait() {
  GaitConfig c;
  c.bob_min_m = c.bob_max_m = 0.02;
  c.roll_min_deg = c.roll_max_deg = 2.0;
  c.pitch_min_deg = c.pitch_max_deg = 2.5;
  return GaitParams::Draw(c, 3, 1);
}

struct Tilt {
  double roll, pitch, yaw;
};
Tilt Angles(const Eigen::Matrix3d& R) {
  return {std::atan2(R(2, 1), R(2, 2)), std::asin(-R(2, 0)), std::atan2(R(1, 0), R(0, 0))};
}

TEST(Gait, BobsAndRocksWhileWalkingAndIsLevelStandingStill) {
  const Trajectory t = WalkingTrajectory(FixedGait());
  double z_max = 0, roll_max = 0, pitch_max = 0;
  for (double s = 0; s <= t.duration_s(); s += 0.002) {
    const Eigen::Isometry3d T = t.Pose(s);
    const Tilt a = Angles(T.linear());
    const PlanarPose p = t.Planar(s);
    // The gait leaves the planar motion alone.
    ASSERT_NEAR(T.translation().x(), p.x, 1e-12);
    ASSERT_NEAR(a.yaw, p.yaw, 1e-9);
    if (s < 1.5 || s > t.duration_s() - 1.5) {
      // Standing (more than the settling time away from any motion): exactly level.
      ASSERT_EQ(T.translation().z(), 0.5) << s;
      ASSERT_EQ(a.roll, 0.0) << s;
      ASSERT_EQ(a.pitch, 0.0) << s;
    }
    z_max = std::max(z_max, std::fabs(T.translation().z() - 0.5));
    roll_max = std::max(roll_max, std::fabs(a.roll));
    pitch_max = std::max(pitch_max, std::fabs(a.pitch));
  }
  EXPECT_GT(z_max, 0.019);
  EXPECT_LE(z_max, 0.02 + 1e-9);
  EXPECT_GT(roll_max, 1.9 * kDeg);
  EXPECT_LE(roll_max, 2.0 * kDeg + 1e-9);
  EXPECT_GT(pitch_max, 2.4 * kDeg);
  EXPECT_LE(pitch_max, 2.5 * kDeg + 1e-9);
}

TEST(Gait, StepRateGrowsWithSpeed) {
  const Trajectory t = WalkingTrajectory(FixedGait());
  // Height bob cycles (upward zero crossings) per second over steady walking.
  auto rate_hz = [&](double from, double to) {
    int crossings = 0;
    double first = -1, last = -1;
    double previous = t.Pose(from).translation().z() - 0.5;
    for (double s = from + 0.001; s <= to; s += 0.001) {
      const double z = t.Pose(s).translation().z() - 0.5;
      if (previous < 0 && z >= 0) {
        if (first < 0) first = s;
        last = s;
        ++crossings;
      }
      previous = z;
    }
    return (crossings - 1) / (last - first);
  };
  // Config: 1.5 Hz standing, 2.5 Hz at 1 m/s, linear in between.
  EXPECT_NEAR(rate_hz(5.0, 12.0), 1.5 + 0.3, 0.05);
  EXPECT_NEAR(rate_hz(16.0, 22.0), 2.5, 0.05);
}

TEST(Gait, PoseHasContinuousDerivatives) {
  const Trajectory t = WalkingTrajectory(FixedGait());
  // Second differences at 1 ms stay at the gait's own accelerations (A (2 pi f)^2: about 5 m/s^2
  // and 11 rad/s^2 here). A kink in the first derivative, e.g. from interpolating the 100 Hz
  // samples linearly, would show as tens of m/s^2 at every sample.
  const double h = 0.001;
  double z_acc = 0, roll_acc = 0, pitch_acc = 0;
  for (double s = h; s + h <= t.duration_s(); s += 0.0007) {
    const Eigen::Isometry3d a = t.Pose(s - h), b = t.Pose(s), c = t.Pose(s + h);
    z_acc = std::max(
        z_acc,
        std::fabs(a.translation().z() - 2 * b.translation().z() + c.translation().z()) / (h * h));
    const Tilt ta = Angles(a.linear()), tb = Angles(b.linear()), tc = Angles(c.linear());
    roll_acc = std::max(roll_acc, std::fabs(ta.roll - 2 * tb.roll + tc.roll) / (h * h));
    pitch_acc = std::max(pitch_acc, std::fabs(ta.pitch - 2 * tb.pitch + tc.pitch) / (h * h));
  }
  const double w = 2 * std::numbers::pi * 2.5;
  EXPECT_LT(z_acc, 1.5 * 0.02 * w * w);
  EXPECT_LT(roll_acc, 1.5 * 2.0 * kDeg * w * w);
  EXPECT_LT(pitch_acc, 1.5 * 2.5 * kDeg * w * w);
  RecordProperty("max_z_acceleration_mps2", std::to_string(z_acc));
}

TEST(Gait, DrawnPerRobotWithinTheConfiguredRanges) {
  const GaitConfig c;
  GaitParams previous;
  for (int robot = 1; robot <= 5; ++robot) {
    const GaitParams g = GaitParams::Draw(c, 1, robot);
    EXPECT_GE(g.bob_m, c.bob_min_m);
    EXPECT_LE(g.bob_m, c.bob_max_m);
    EXPECT_GE(g.roll_rad, c.roll_min_deg * kDeg);
    EXPECT_LE(g.roll_rad, c.roll_max_deg * kDeg);
    EXPECT_GE(g.pitch_rad, c.pitch_min_deg * kDeg);
    EXPECT_LE(g.pitch_rad, c.pitch_max_deg * kDeg);
    EXPECT_NE(g.bob_m, previous.bob_m);
    previous = g;
  }
  GaitConfig off;
  off.enabled = false;
  const Trajectory level = WalkingTrajectory(GaitParams::Draw(off, 1, 1));
  EXPECT_EQ(level.Pose(15.0).translation().z(), 0.5);
}

// A 120 s walk with every odometry error off except many slips: the integrated odometry departs
// from the truth only inside the events mission.txt lists, by the magnitudes it lists.
TEST(SlipEvents, OdometryIsWrongExactlyWhereMissionTxtSays) {
  std::string error;
  const World world =
      LoadWorld(std::string(MSGRAPHS_WORLDS_DIR) + "/construction.world", error).value();
  const Scene scene(world, 0);
  MissionConfig mc;
  mc.robots = 1;
  mc.duration_s = 120;
  mc.seed = 4;
  mc.shared_rooms = 0;
  const Mission mission = PlanMission(world, scene, mc, error).value();
  const RobotPlan& robot = mission.robots[0];
  TempDir dir("slip");
  OdometrySimConfig config;
  config.scale_error_min = config.scale_error_max = 0.0;
  config.yaw_drift_deg_per_10m = 0.0;
  config.noise_xy_m = config.noise_yaw_rad = config.noise_z_m = config.noise_roll_pitch_rad = 0.0;
  config.drop_probability = 0.0;
  config.slip.enabled = true;
  config.slip.per_100m_min = config.slip.per_100m_max = 10.0;
  RobotReport report;
  report.plan = &robot;
  report.clocks = RobotClocks::Draw(4, robot.id);
  const std::string log = (dir.path / "odometry.log").string();
  ASSERT_TRUE(RenderOdometry(robot.trajectory, config, report.clocks, 4, robot.id, log,
                             report.odometry, error))
      << error;
  ASSERT_TRUE(WriteMissionTxt(world, mission, {}, {report}, (dir.path / "mission.txt").string()));

  // The events as mission.txt has them.
  struct Event {
    double start_s, duration_s, scale, yaw_rad, true_m;
  };
  std::vector<Event> events;
  std::ifstream in(dir.path / "mission.txt");
  for (std::string line; std::getline(in, line);) {
    std::istringstream s(line);
    std::string word, key, kind;
    s >> word;
    if (word != "slip") continue;
    Event e{};
    int id = 0;
    double yaw_deg = 0;
    s >> key >> id >> key >> e.start_s >> key >> e.duration_s >> key >> kind >> key >> e.scale >>
        key >> yaw_deg >> key >> e.true_m;
    ASSERT_TRUE(s) << line;
    e.yaw_rad = yaw_deg * kDeg;
    events.push_back(e);
  }
  const double walked_m = report.odometry.path_length_m;
  ASSERT_GT(walked_m, 60.0);
  EXPECT_EQ(events.size(), report.odometry.slips.size());
  EXPECT_GT(static_cast<double>(events.size()), 0.5 * walked_m / 10.0) << "about 10 per 100 m";
  EXPECT_LT(static_cast<double>(events.size()), 1.6 * walked_m / 10.0);

  // Per sample: the reported step (through the drivers) against the true one.
  namespace can = drivers::can_odometry;
  auto reader = can::CandumpFileReader::Open(log.c_str()).value();
  auto stream = can::OdometryStream::Create({}).value();
  can::CandumpLine line;
  std::vector<can::Pose3> steps;
  while (reader.Next(line).value()) {
    if (stream.Add(line.frame, line.stamp)) steps.push_back(stream.pose().T_previous_current);
  }
  ASSERT_EQ(steps.size(), report.odometry.samples);
  std::vector<double> length_error(events.size(), 0.0), yaw_error(events.size(), 0.0);
  std::vector<int> counted(events.size(), 0);
  double worst_outside_m = 0, worst_outside_rad = 0;
  for (std::size_t i = 1; i < steps.size(); ++i) {
    const double t = 0.02 * static_cast<double>(i + 1);  // sample i + 1 ends at t (no delay)
    const Eigen::Isometry3d truth =
        robot.trajectory.Pose(t - 0.02).inverse() * robot.trajectory.Pose(t);
    const can::Pose3& o = steps[i];
    const double dl = std::hypot(o.x_m, o.y_m) - truth.translation().head<2>().norm();
    const double dyaw =
        std::atan2(2 * (o.qw * o.qz + o.qx * o.qy), 1 - 2 * (o.qy * o.qy + o.qz * o.qz)) -
        std::atan2(truth.linear()(1, 0), truth.linear()(0, 0));
    int in_event = -1;
    for (std::size_t e = 0; e < events.size(); ++e) {
      if (t > events[e].start_s + 1e-6 && t <= events[e].start_s + events[e].duration_s + 1e-6)
        in_event = static_cast<int>(e);
    }
    if (in_event < 0) {
      worst_outside_m = std::max(worst_outside_m, std::fabs(dl));
      worst_outside_rad = std::max(worst_outside_rad, std::fabs(dyaw));
    } else {
      length_error[static_cast<std::size_t>(in_event)] += dl;
      yaw_error[static_cast<std::size_t>(in_event)] += dyaw;
      ++counted[static_cast<std::size_t>(in_event)];
    }
  }
  // Outside the events only the DBC's quantisation (0.1 mm, 1e-5 rad) is left.
  EXPECT_LT(worst_outside_m, 1.5e-4);
  EXPECT_LT(worst_outside_rad, 2e-5);
  for (std::size_t e = 0; e < events.size(); ++e) {
    const double n = events[e].duration_s / 0.02;
    EXPECT_NEAR(length_error[e], (events[e].scale - 1.0) * events[e].true_m, 1e-3 + 1e-4 * n)
        << "event " << e;
    EXPECT_NEAR(yaw_error[e], events[e].yaw_rad, 2e-5 * std::sqrt(n) + 1e-5)
        << "event " << e << " at " << events[e].start_s << " s, " << counted[e] << " samples of "
        << n;
  }
}

TEST(SlipEvents, OffMeansNoneAndLeavesTheOtherErrorsAlone) {
  Trajectory t = WalkingTrajectory(FixedGait());
  const RobotClocks clocks = RobotClocks::Draw(9, 1);
  TempDir dir("slip_off");
  OdometrySimConfig on, off;
  on.slip.enabled = true;
  on.slip.per_100m_min = on.slip.per_100m_max = 30.0;  // 15 m walked: a few events
  off.slip.enabled = false;
  OdometrySimStats s_on, s_off;
  std::string error;
  ASSERT_TRUE(RenderOdometry(t, on, clocks, 9, 1, (dir.path / "on.log").string(), s_on, error));
  ASSERT_TRUE(RenderOdometry(t, off, clocks, 9, 1, (dir.path / "off.log").string(), s_off, error));
  EXPECT_GT(s_on.slips.size(), 0u);
  EXPECT_EQ(s_off.slips.size(), 0u);
  EXPECT_EQ(s_off.slip_per_100m, 0.0);
  EXPECT_EQ(s_on.scale_error, s_off.scale_error);
  EXPECT_EQ(s_on.dropped, s_off.dropped);
}

TEST(TruthRate, TumFilesHaveTheRequestedSpacing) {
  const Trajectory t = WalkingTrajectory(FixedGait());
  RobotClocks clocks = RobotClocks::Draw(2, 1);
  clocks.start_delay_s = 12.5;
  TempDir dir("tum_rate");
  for (const double rate : {10.0, 50.0, 1000.0}) {
    const fs::path path = dir.path / ("truth_" + std::to_string(static_cast<int>(rate)) + ".tum");
    ASSERT_TRUE(WriteTum(t, clocks, rate, path.string()));
    std::ifstream in(path);
    std::vector<std::array<double, 8>> rows;
    for (std::string line; std::getline(in, line);) {
      std::istringstream s(line);
      std::array<double, 8> r{};
      for (double& v : r) s >> v;
      ASSERT_TRUE(s) << line;
      rows.push_back(r);
    }
    ASSERT_EQ(rows.size(), static_cast<std::size_t>(std::floor(t.duration_s() * rate + 1e-9)) + 1)
        << rate;
    EXPECT_NEAR(rows.front()[0], clocks.Host(0.0).seconds_since_epoch(), 1e-6);
    for (std::size_t i = 1; i < rows.size(); ++i) {
      ASSERT_NEAR(rows[i][0] - rows[i - 1][0], 1.0 / rate, 2.5e-6) << rate << " Hz, row " << i;
    }
    // The full 6-DOF pose at each stamp (a row in the middle of the walk).
    const std::size_t k = rows.size() / 2;
    const Eigen::Isometry3d T = t.Pose(static_cast<double>(k) / rate);
    const Eigen::Quaterniond q(T.linear());
    EXPECT_NEAR(rows[k][3], T.translation().z(), 1e-6);
    EXPECT_NEAR(std::fabs(rows[k][4] * q.x() + rows[k][5] * q.y() + rows[k][6] * q.z() +
                          rows[k][7] * q.w()),
                1.0, 1e-8);
  }
}

}  // namespace
}  // namespace msgraphs::sim
