// SPDX-License-Identifier: MIT
// The simulator's recordings checked with the project's own drivers: decoding the generated
// pcap puts the points on the world's surfaces within the noise model; integrating the
// generated candump log reproduces the ground truth within the configured errors, and the
// error statistics match the configuration; the same seed gives the same bytes.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <vector>

#include "../drivers/velodyne_capture.hpp"
#include "clocks.hpp"
#include "lidar_sim.hpp"
#include "mission.hpp"
#include "mission_output.hpp"
#include "msgraphs/drivers/can_odometry/candump_file.hpp"
#include "msgraphs/drivers/can_odometry/odometry_stream.hpp"
#include "msgraphs/drivers/velodyne/data_packet_decoder.hpp"
#include "msgraphs/drivers/velodyne/device_clock.hpp"
#include "odometry_sim.hpp"
#include "scene.hpp"
#include "world.hpp"

namespace msgraphs::sim {
namespace {

namespace fs = std::filesystem;

struct Fixture {
  World world;
  std::unique_ptr<Scene> scene;
  Mission mission;
  fs::path dir;

  Fixture(const char* world_file, double duration_s, std::uint64_t seed) {
    std::string error;
    world = LoadWorld(std::string(MSGRAPHS_WORLDS_DIR) + "/" + world_file, error).value();
    scene = std::make_unique<Scene>(world, 0);
    MissionConfig config;
    config.robots = 1;
    config.duration_s = duration_s;
    config.seed = seed;
    config.shared_rooms = 0;
    mission = PlanMission(world, *scene, config, error).value();
    dir = fs::temp_directory_path() /
          ("msgraphs_sim_" + std::to_string(getpid()) + "_" + std::to_string(seed));
    fs::create_directories(dir);
  }
  ~Fixture() { fs::remove_all(dir); }
};

double Percentile(std::vector<double> v, double q) {
  std::nth_element(v.begin(),
                   v.begin() + static_cast<std::ptrdiff_t>(q * static_cast<double>(v.size() - 1)),
                   v.end());
  return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1))];
}

class LidarOnSurfaces : public ::testing::TestWithParam<const char*> {};

TEST_P(LidarOnSurfaces, DecodedPointsLieOnTheWorldWithinTheNoiseModel) {
  Fixture f(GetParam(), 12.0, 11);
  const RobotPlan& robot = f.mission.robots[0];
  const RobotClocks clocks = RobotClocks::Draw(11, robot.id);
  LidarSimConfig config;
  LidarSimStats stats;
  std::string error;
  const std::string pcap = (f.dir / "velodyne.pcap").string();
  ASSERT_TRUE(
      RenderLidar(*f.scene, robot.trajectory, config, clocks, 11, robot.id, pcap, stats, error))
      << error;
  EXPECT_GT(static_cast<double>(stats.returns) / static_cast<double>(stats.rays), 0.95)
      << "indoors nearly every ray returns";

  // Through the drivers, as a robot would: pcap -> UDP payloads -> decoder -> device clock.
  const auto capture = test::LoadCapture(pcap);
  ASSERT_TRUE(capture.read_to_end);
  EXPECT_EQ(capture.data.size(), stats.data_packets);
  EXPECT_EQ(capture.position.size(), stats.position_packets);
  const auto decoder = drivers::velodyne::DataPacketDecoder::Create({}).value();
  drivers::velodyne::DeviceClockSync sync;
  std::vector<drivers::velodyne::VelodynePoint> out(drivers::velodyne::kMaxPointsPerPacket);
  std::vector<double> residuals;
  const std::int64_t host0 = clocks.Host(0.0).nanoseconds_since_epoch();
  for (std::size_t k = 0; k < capture.data.size(); ++k) {
    auto r = decoder.Decode(capture.data[k].bytes, out);
    ASSERT_TRUE(r.has_value()) << r.error().detail;
    const UnixTime first = sync.Map(capture.data[k].time, r->device_time_us, r->packet_duration_ns);
    if (k % 7 != 0) continue;  // a sample of the packets keeps the test fast
    for (std::size_t i = 0; i < r->points; ++i) {
      const auto& p = out[i];
      const double t =
          static_cast<double>(first.nanoseconds_since_epoch() - host0 + p.time_offset_ns) * 1e-9;
      const Eigen::Vector3d world_point =
          robot.trajectory.Pose(t) * config.T_base_lidar *
          Eigen::Vector3d(static_cast<double>(p.x_m), static_cast<double>(p.y_m),
                          static_cast<double>(p.z_m));
      residuals.push_back(f.scene->DistanceToSurface(world_point, 1.5));
    }
  }
  ASSERT_GT(residuals.size(), 50000u);
  double sum_sq = 0;
  for (double r : residuals) sum_sq += r * r;
  const double rms = std::sqrt(sum_sq / static_cast<double>(residuals.size()));
  // Range noise is 3 cm along the ray; the distance to the surface is at most that (less at
  // oblique incidence, more where the nearest surface is another one near a corner).
  EXPECT_LT(rms, 0.035);
  EXPECT_GT(rms, 0.015);
  EXPECT_LT(Percentile(residuals, 0.5), 0.03);
  EXPECT_LT(Percentile(residuals, 0.999), 0.15);
  RecordProperty("rms_m", std::to_string(rms));
}

INSTANTIATE_TEST_SUITE_P(Worlds,
                         LidarOnSurfaces,
                         ::testing::Values("office.world", "rotated.world"));

// Integrates a candump log through OdometryStream; returns the poses (and the stream's stats).
std::vector<drivers::can_odometry::OdometryPose> Integrate(
    const std::string& path, drivers::can_odometry::OdometryStreamStats& stats) {
  namespace can = drivers::can_odometry;
  auto reader = can::CandumpFileReader::Open(path.c_str()).value();
  auto stream = can::OdometryStream::Create({}).value();
  std::vector<can::OdometryPose> poses;
  can::CandumpLine line;
  while (reader.Next(line).value()) {
    if (stream.Add(line.frame, line.stamp)) poses.push_back(stream.pose());
  }
  EXPECT_EQ(reader.stats().malformed, 0u);
  stats = stream.stats();
  return poses;
}

double Yaw(const drivers::can_odometry::Pose3& p) {
  return std::atan2(2.0 * (p.qw * p.qz + p.qx * p.qy), 1.0 - 2.0 * (p.qy * p.qy + p.qz * p.qz));
}

// With every error off (slips too), the candump log integrated by the drivers is the true
// 6-DOF motion: the gait's height bob and roll and pitch rocking included.
TEST(OdometryRecording, WithoutErrorsItReproducesTheGroundTruth) {
  Fixture f("apartment.world", 120.0, 21);
  const RobotPlan& robot = f.mission.robots[0];
  const RobotClocks clocks = RobotClocks::Draw(21, robot.id);
  OdometrySimConfig config;
  config.scale_error_min = config.scale_error_max = 0.0;
  config.yaw_drift_deg_per_10m = 0.0;
  config.noise_xy_m = config.noise_yaw_rad = 0.0;
  config.noise_z_m = config.noise_roll_pitch_rad = 0.0;
  config.drop_probability = 0.0;
  config.slip.enabled = false;
  OdometrySimStats stats;
  std::string error;
  const std::string log = (f.dir / "odometry.log").string();
  ASSERT_TRUE(RenderOdometry(robot.trajectory, config, clocks, 21, robot.id, log, stats, error))
      << error;
  EXPECT_TRUE(stats.slips.empty());
  drivers::can_odometry::OdometryStreamStats s;
  const auto poses = Integrate(log, s);
  ASSERT_EQ(poses.size(), stats.samples);
  EXPECT_EQ(s.crc_errors + s.bad_frames + s.foreign_ids, 0u);
  // Odometry starts at the identity at the first sample (t = 0.02 s): compare in that frame.
  const Eigen::Isometry3d T0 = robot.trajectory.Pose(0.02);
  double worst_xy = 0, worst_z = 0, worst_rotation = 0, max_tilt = 0, z_lo = 1e9, z_hi = -1e9;
  for (const auto& p : poses) {
    const double t = (p.stamp - clocks.Host(0.0)).seconds();
    const Eigen::Isometry3d truth = T0.inverse() * robot.trajectory.Pose(t);
    const auto& o = p.T_odom_base;
    worst_xy = std::max(
        worst_xy, std::hypot(o.x_m - truth.translation().x(), o.y_m - truth.translation().y()));
    worst_z = std::max(worst_z, std::fabs(o.z_m - truth.translation().z()));
    const Eigen::Quaterniond q(o.qw, o.qx, o.qy, o.qz);
    worst_rotation =
        std::max(worst_rotation,
                 Eigen::AngleAxisd(q.toRotationMatrix().transpose() * truth.linear()).angle());
    const Eigen::Matrix3d R_world = robot.trajectory.Pose(t).linear();
    max_tilt = std::max(max_tilt, std::acos(std::clamp(R_world(2, 2), -1.0, 1.0)));
    z_lo = std::min(z_lo, truth.translation().z());
    z_hi = std::max(z_hi, truth.translation().z());
  }
  // The motion is not planar: the base tilts by degrees and bobs by centimetres...
  EXPECT_GT(max_tilt, 1.0 * std::numbers::pi / 180.0);
  EXPECT_GT(z_hi - z_lo, 0.015);
  // ... and only the DBC's quantisation (0.1 mm, 1e-5 rad per sample) separates the two.
  EXPECT_LT(worst_xy, 0.05) << "over " << stats.path_length_m << " m";
  EXPECT_LT(worst_z, 0.01);
  EXPECT_LT(worst_rotation, 0.002);
  RecordProperty("worst_xy_m", std::to_string(worst_xy));
  RecordProperty("worst_rotation_rad", std::to_string(worst_rotation));
}

TEST(OdometryRecording, ErrorStatisticsMatchTheConfiguration) {
  Fixture f("construction.world", 240.0, 5);
  const RobotPlan& robot = f.mission.robots[0];
  const RobotClocks clocks = RobotClocks::Draw(5, robot.id);
  OdometrySimConfig config;
  config.drop_probability = 0.005;
  config.slip.enabled = false;  // slips have their own test (slip_test.cpp)
  OdometrySimStats stats;
  std::string error;
  const std::string log = (f.dir / "odometry.log").string();
  ASSERT_TRUE(RenderOdometry(robot.trajectory, config, clocks, 5, robot.id, log, stats, error))
      << error;
  EXPECT_GE(std::fabs(stats.scale_error), 0.01);
  EXPECT_LE(std::fabs(stats.scale_error), 0.02);
  drivers::can_odometry::OdometryStreamStats s;
  const auto poses = Integrate(log, s);
  // Every sample the simulator dropped is detected as missing and bridged.
  EXPECT_EQ(s.integration.missing_samples, stats.dropped);
  EXPECT_GT(stats.dropped, 0u);

  // Scale: odometry chord lengths over true ones, over 1 s windows while walking (chords
  // average out the per-sample noise that would inflate a summed path length).
  const double t_host0 = clocks.Host(0.0).seconds_since_epoch();
  double odom_chords = 0, true_chords = 0;
  for (std::size_t i = 0; i + 50 < poses.size(); i += 50) {
    const auto& a = poses[i].T_odom_base;
    const auto& b = poses[i + 50].T_odom_base;
    const PlanarPose ta = robot.trajectory.Planar(poses[i].stamp.seconds_since_epoch() - t_host0);
    const PlanarPose tb =
        robot.trajectory.Planar(poses[i + 50].stamp.seconds_since_epoch() - t_host0);
    const double true_chord = std::hypot(tb.x - ta.x, tb.y - ta.y);
    if (true_chord < 0.5) continue;
    true_chords += true_chord;
    odom_chords += std::hypot(b.x_m - a.x_m, b.y_m - a.y_m);
  }
  ASSERT_GT(true_chords, 50.0);
  EXPECT_NEAR(odom_chords / true_chords - 1.0, stats.scale_error, 0.002);
  RecordProperty("measured_scale_error", std::to_string(odom_chords / true_chords - 1.0));
  const double true_length =
      robot.trajectory.PathLength(poses.back().stamp.seconds_since_epoch() - t_host0);
  // Yaw drift: heading error per metre travelled, against the configured rate.
  const Eigen::Isometry3d T0 = robot.trajectory.Pose(0.02);
  const double t_end = (poses.back().stamp - clocks.Host(0.0)).seconds();
  const Eigen::Isometry3d truth_end = T0.inverse() * robot.trajectory.Pose(t_end);
  const double true_yaw = std::atan2(truth_end.linear()(1, 0), truth_end.linear()(0, 0));
  const double yaw_error =
      std::remainder(Yaw(poses.back().T_odom_base) - true_yaw, 2 * std::numbers::pi);
  const double rate = yaw_error / true_length;
  EXPECT_NEAR(rate, stats.yaw_drift_rad_per_m, 0.2 * std::fabs(stats.yaw_drift_rad_per_m))
      << "measured " << rate * 10 * 180 / std::numbers::pi << " deg/10 m, configured "
      << stats.yaw_drift_rad_per_m * 10 * 180 / std::numbers::pi;
  RecordProperty("measured_drift_deg_per_10m", std::to_string(rate * 10 * 180 / std::numbers::pi));
}

std::string Slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Every output file of a mission (people, start delays, slips and gait on) is the same byte
// for byte whatever the thread count; another seed changes the recordings.
TEST(SimulatorDeterminism, SameSeedSameBytesOtherSeedOtherBytes) {
  const std::string world_path = std::string(MSGRAPHS_WORLDS_DIR) + "/office.world";
  auto render = [&](std::uint64_t seed, int threads, const fs::path& dir) {
    std::string error;
    const World world = LoadWorld(world_path, error).value();
    const Scene scene(world, 0);
    MissionConfig mc;
    mc.robots = 2;
    mc.duration_s = 6;
    mc.seed = seed;
    mc.shared_rooms = 0;
    mc.people.count = 2;
    mc.start_delays.mode = StartDelays::Mode::kRandom;
    mc.visit_kinds = VisitKinds::Benchmark();
    const Mission m = PlanMission(world, scene, mc, error).value();
    OutputConfig oc;
    oc.lidar.threads = threads;
    oc.world_path = world_path;
    oc.start_delays = "random";
    oc.odometry.slip.enabled = true;
    EXPECT_TRUE(WriteMissionOutputs(world, scene, m, oc, dir.string(), error)) << error;
  };
  const fs::path base = fs::temp_directory_path() / ("msgraphs_det_" + std::to_string(getpid()));
  render(1, 1, base / "a");
  render(1, 2, base / "b");  // thread count must not matter
  render(2, 2, base / "c");
  std::size_t files = 0;
  for (const auto& entry : fs::recursive_directory_iterator(base / "a")) {
    if (!entry.is_regular_file()) continue;
    const fs::path rel = fs::relative(entry.path(), base / "a");
    EXPECT_EQ(Slurp(entry.path()), Slurp(base / "b" / rel)) << rel;
    ++files;
  }
  EXPECT_EQ(files, 16u);  // mission.txt, world, svg; 5 truth files; 4 per robot
  EXPECT_NE(Slurp(base / "a" / "robot1" / "velodyne.pcap"),
            Slurp(base / "c" / "robot1" / "velodyne.pcap"));
  EXPECT_NE(Slurp(base / "a" / "robot2" / "odometry.log"),
            Slurp(base / "c" / "robot2" / "odometry.log"));
  fs::remove_all(base);
}

}  // namespace
}  // namespace msgraphs::sim
