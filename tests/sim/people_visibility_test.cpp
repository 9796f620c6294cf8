// SPDX-License-Identifier: MIT
// People in the lidar (points on a walking person, at the person's true position at each
// firing), and the shared-structure truth: which wall faces each robot saw, and what a robot
// pair shares (a pair in one room shares walls in both directions; a pair in rooms that do not
// see each other shares none).
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <vector>

#include "../drivers/velodyne_capture.hpp"
#include "clocks.hpp"
#include "lidar_sim.hpp"
#include "msgraphs/drivers/velodyne/data_packet_decoder.hpp"
#include "msgraphs/drivers/velodyne/device_clock.hpp"
#include "people.hpp"
#include "scene.hpp"
#include "shared_truth.hpp"
#include "trajectory.hpp"
#include "visibility.hpp"
#include "world.hpp"

namespace msgraphs::sim {
namespace {

namespace fs = std::filesystem;

Trajectory Standing(double x, double y, double yaw, double seconds, double start_s = 0) {
  Trajectory t(0.01, 0.5);
  for (int i = 0; i <= static_cast<int>(std::lround(seconds / 0.01)); ++i) t.Append({x, y, yaw});
  t.set_start_s(start_s);
  GaitConfig off;
  off.enabled = false;
  t.SetGait(GaitParams::Draw(off, 1, 1));
  return t;
}

struct DecodedPoint {
  double t;  ///< mission time of the firing
  Eigen::Vector3d world;
};

// The pcap through the project's drivers, each point in the world with the true pose.
std::vector<DecodedPoint> Decode(const std::string& pcap,
                                 const Trajectory& trajectory,
                                 const RobotClocks& clocks,
                                 const LidarSimConfig& config) {
  const auto capture = test::LoadCapture(pcap);
  EXPECT_TRUE(capture.read_to_end);
  const auto decoder = drivers::velodyne::DataPacketDecoder::Create({}).value();
  drivers::velodyne::DeviceClockSync sync;
  std::vector<drivers::velodyne::VelodynePoint> out(drivers::velodyne::kMaxPointsPerPacket);
  std::vector<DecodedPoint> points;
  const std::int64_t host0 = clocks.Host(0.0).nanoseconds_since_epoch();
  for (const auto& packet : capture.data) {
    auto r = decoder.Decode(packet.bytes, out);
    if (!r) continue;
    const UnixTime first = sync.Map(packet.time, r->device_time_us, r->packet_duration_ns);
    for (std::size_t i = 0; i < r->points; ++i) {
      const auto& p = out[i];
      const double t =
          static_cast<double>(first.nanoseconds_since_epoch() - host0 + p.time_offset_ns) * 1e-9;
      points.push_back({trajectory.start_s() + t,
                        trajectory.Pose(t) * config.T_base_lidar *
                            Eigen::Vector3d(static_cast<double>(p.x_m), static_cast<double>(p.y_m),
                                            static_cast<double>(p.z_m))});
    }
  }
  return points;
}

// A person crosses the office corridor 2-4 m in front of a robot standing still.
TEST(People, PointsOnAPersonAtItsTruePositionAtEachFiring) {
  std::string error;
  const World world = LoadWorld(std::string(MSGRAPHS_WORLDS_DIR) + "/office.world", error).value();
  const Scene scene(world, 0);
  const Trajectory robot = Standing(20.0, 1.2, 0.0, 3.0, 10.0);  // starts 10 s into the mission
  Person person;
  person.id = 1;
  person.radius_m = 0.25;
  person.height_m = 1.75;
  person.knots = {{10.0, {22.0, 0.6}}, {13.0, {25.0, 1.8}}};  // 1.08 m/s, diagonally
  const std::vector<Person> people{person};
  const PeopleScene people_scene(people, scene.floor_z());
  const RobotClocks clocks = RobotClocks::Draw(3, 1);
  LidarSimConfig config;
  LidarSimStats stats;
  const fs::path dir = fs::temp_directory_path() / ("msgraphs_people_" + std::to_string(getpid()));
  fs::create_directories(dir);
  ASSERT_TRUE(RenderLidar(scene, robot, config, clocks, 3, 1, (dir / "v.pcap").string(), stats,
                          error, &people_scene))
      << error;
  const auto points = Decode((dir / "v.pcap").string(), robot, clocks, config);
  fs::remove_all(dir);
  ASSERT_GT(stats.person_returns, 2000u);

  // Points near the person's axis at their own firing time, and the same test with the person
  // where it was 0.3 s later (the person moved 0.32 m): the points follow the true motion.
  auto residuals = [&](double time_shift_s) {
    std::vector<double> r;
    for (const DecodedPoint& p : points) {
      Eigen::Vector2d c, v;
      person.StateAt(p.t + time_shift_s, c, v);
      const double d = (p.world.head<2>() - c).norm();
      if (d < 0.6 && p.world.z() > 0.1 && p.world.z() < person.height_m &&
          scene.DistanceToSurface(p.world, 1.0) > 0.15)
        r.push_back(std::fabs(d - person.radius_m));
    }
    std::sort(r.begin(), r.end());
    return r;
  };
  const auto now = residuals(0.0), later = residuals(0.3);
  ASSERT_GT(now.size(), 2000u);
  // The returns from the person lie on its surface (3 cm range noise, 2 mm quantisation); all
  // of them but those near the floor (left out above) are found there, and nothing else is.
  EXPECT_LT(now[now.size() / 2], 0.03);
  EXPECT_LT(now[now.size() * 99 / 100], 0.10);
  EXPECT_LE(static_cast<double>(now.size()), 1.01 * static_cast<double>(stats.person_returns));
  EXPECT_GT(static_cast<double>(now.size()), 0.85 * static_cast<double>(stats.person_returns));
  EXPECT_GT(later.size() > 0 ? later[later.size() / 2] : 1.0, 0.08);
  RecordProperty("median_residual_m", std::to_string(now[now.size() / 2]));
}

TEST(People, PlannedWalksAreInsideTheBuildingAtWalkingSpeed) {
  std::string error;
  const World world =
      LoadWorld(std::string(MSGRAPHS_WORLDS_DIR) + "/apartment.world", error).value();
  const Scene scene(world, 0);
  const NavGrid grid(world, scene, 0, 1.0);
  std::vector<int> rooms;
  std::vector<std::vector<Eigen::Vector2d>> free;
  for (std::size_t r = 0; r < world.rooms.size(); ++r) {
    auto cells = grid.FreeCells(static_cast<int>(r), 0.55);
    if (cells.size() < 4) continue;
    rooms.push_back(static_cast<int>(r));
    free.push_back(std::move(cells));
  }
  PeopleConfig config;
  config.count = 4;
  const auto people = PlanPeople(world, grid, rooms, free, config, 120.0, 8);
  ASSERT_EQ(people.size(), 4u);
  for (const Person& p : people) {
    EXPECT_GE(p.height_m, 1.6);
    EXPECT_LE(p.height_m, 1.9);
    EXPECT_GE(p.speed_mps, 0.8);
    EXPECT_LE(p.speed_mps, 1.4);
    ASSERT_GT(p.knots.size(), 4u);
    EXPECT_GE(p.knots.back().t_s, 120.0);
    for (double t = 0; t < 120.0; t += 0.1) {
      Eigen::Vector2d c, v;
      p.StateAt(t, c, v);
      ASSERT_LE(v.norm(), p.speed_mps + 1e-9);
      ASSERT_NE(world.RoomAt(c, 0), nullptr) << "person " << p.id << " at " << t;
    }
  }
}

// Two 6 x 6 m rooms side by side, no door between them.
constexpr const char* kTwoRooms = R"(msgraphs-world 1
name two rooms
level 0 0.0 3.0
wall s 0 0 12 0 0.2 3.0
wall n 0 6 12 6 0.2 3.0
wall w 0 0 0 6 0.2 3.0
wall e 12 0 12 6 0.2 3.0
wall mid 6 0 6 6 0.2 3.0
room A a 0 0 6 0 6 6 0 6
room B b 6 0 12 0 12 6 6 6
box 4.5 4.5 0 0.8 0.8 1.0
)";

TEST(SharedTruth, APairInOneRoomSharesWallsAPairApartSharesNone) {
  ParseError parse_error;
  const World world = ParseWorld(kTwoRooms, parse_error).value();
  const Scene scene(world, 0);
  const std::vector<Trajectory> robots{Standing(2.0, 3.0, 0.3, 2.0), Standing(9.0, 2.5, 2.0, 2.0),
                                       Standing(3.5, 1.5, -1.0, 2.0)};
  std::vector<WallVisibility> visibility;
  std::vector<RobotTruth> truth;
  const fs::path dir = fs::temp_directory_path() / ("msgraphs_shared_" + std::to_string(getpid()));
  fs::create_directories(dir);
  visibility.reserve(robots.size());
  for (std::size_t i = 0; i < robots.size(); ++i) {
    visibility.emplace_back(world, 0);
    const int id = static_cast<int>(i) + 1;
    const RobotClocks clocks = RobotClocks::Draw(5, id);
    LidarSimStats stats;
    std::string error;
    ASSERT_TRUE(RenderLidar(scene, robots[i], {}, clocks, 5, id, (dir / "v.pcap").string(), stats,
                            error, nullptr, &visibility.back()));
    // Every wall-face return is in the bins, and nothing else is.
    std::uint64_t binned = 0;
    for (std::size_t w = 0; w < visibility.back().walls(); ++w) {
      for (const int face : {1, -1}) {
        for (int b = 0; b < visibility.back().bins(w); ++b)
          binned += visibility.back().hits(w, face, b);
      }
    }
    EXPECT_EQ(binned, stats.wall_returns);
    EXPECT_LT(stats.wall_returns, stats.returns);  // floor, ceiling and the box are not walls
    truth.push_back({id, &robots[i], &visibility.back(), {}});
  }
  // The outside faces of the outer walls (face b of s, face a of n, ...) were never seen.
  for (std::size_t w = 0; w < 4; ++w) {
    const Wall& wall = world.walls[w];
    const int outside = wall.normal().dot(Eigen::Vector2d(6, 3) - wall.start) > 0 ? -1 : 1;
    for (int b = 0; b < visibility[0].bins(w); ++b) {
      for (const auto& v : visibility) EXPECT_EQ(v.hits(w, outside, b), 0u) << wall.id;
    }
  }
  const auto pairs = ComputeSharing(world, 0, truth, 10);
  ASSERT_EQ(pairs.size(), 3u);
  const PairSharing& apart = pairs[0];     // robots 1 and 2
  const PairSharing& together = pairs[1];  // robots 1 and 3
  EXPECT_EQ(apart.robot_b, 2);
  EXPECT_TRUE(apart.rooms_both_inside.empty());
  EXPECT_EQ(apart.shared_wall_m, 0.0) << "opposite faces of the middle wall are different faces";
  EXPECT_EQ(apart.eig_min_m, 0.0);
  EXPECT_EQ(together.robot_b, 3);
  ASSERT_EQ(together.rooms_both_inside.size(), 1u);
  EXPECT_EQ(together.rooms_both_inside[0], "A");
  // Room A's four faces, 6 m each, less what the box hides from one of them.
  EXPECT_GT(together.shared_wall_m, 18.0);
  EXPECT_LE(together.shared_wall_m, 24.0);
  EXPECT_EQ(together.shared_faces, 4);
  EXPECT_GT(together.eig_min_m, 8.0) << "walls in both directions constrain both";
  EXPECT_EQ(pairs[2].shared_wall_m, 0.0);

  ASSERT_TRUE(WriteVisibilityCsv(truth, (dir / "visibility.csv").string()));
  ASSERT_TRUE(WriteSharedCsv(pairs, 10, (dir / "shared.csv").string()));
  std::ifstream shared(dir / "shared.csv");
  std::string header, row12, row13;
  std::getline(shared, header);
  std::getline(shared, row12);
  std::getline(shared, row13);
  EXPECT_EQ(header.rfind("robot_a,robot_b,rooms_both_inside,", 0), 0u);
  EXPECT_EQ(row12.rfind("1,2,,,,0.00,0,", 0), 0u) << row12;
  EXPECT_EQ(row13.rfind("1,3,A,,,", 0), 0u) << row13;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace msgraphs::sim
