// SPDX-License-Identifier: MIT
#include "mission_output.hpp"

#include <chrono>
#include <cstdio>
#include <filesystem>

#include "people.hpp"
#include "shared_truth.hpp"
#include "truth.hpp"
#include "visibility.hpp"

namespace msgraphs::sim {

bool WriteMissionOutputs(const World& world,
                         const Scene& scene,
                         const Mission& mission,
                         const OutputConfig& config,
                         const std::string& out_dir,
                         std::string& error) {
  namespace fs = std::filesystem;
  const int level = mission.config.level;
  const fs::path out(out_dir);
  const fs::path truth_dir = out / "truth";
  std::error_code ec;
  fs::create_directories(truth_dir, ec);
  if (ec) {
    error = truth_dir.string() + ": " + ec.message();
    return false;
  }
  if (!config.world_path.empty())
    fs::copy_file(config.world_path, out / "world.world", fs::copy_options::overwrite_existing, ec);
  if (ec || !WriteWallsCsv(world, (truth_dir / "walls.csv").string()) ||
      !WriteRoomsCsv(world, (truth_dir / "rooms.csv").string()) ||
      !WritePeopleCsv(mission, (truth_dir / "people.csv").string()) ||
      !WriteSvg(world, &mission, level, (out / "map.svg").string())) {
    error = "cannot write the world's truth files in " + out_dir;
    return false;
  }
  const PeopleScene people(mission.people, scene.floor_z());
  std::vector<RobotReport> reports;
  std::vector<WallVisibility> visibility;
  visibility.reserve(mission.robots.size());  // RobotTruth points into it
  std::vector<RobotTruth> truths;
  for (const RobotPlan& plan : mission.robots) {
    const fs::path dir = out / ("robot" + std::to_string(plan.id));
    fs::create_directories(dir, ec);
    RobotReport report;
    report.plan = &plan;
    report.clocks = RobotClocks::Draw(mission.config.seed, plan.id);
    report.clocks.start_delay_s = plan.start_delay_s;
    visibility.emplace_back(world, level);
    const auto r0 = std::chrono::steady_clock::now();
    if (ec ||
        !RenderLidar(scene, plan.trajectory, config.lidar, report.clocks, mission.config.seed,
                     plan.id, (dir / "velodyne.pcap").string(), report.lidar, error,
                     mission.people.empty() ? nullptr : &people, &visibility.back()) ||
        !RenderOdometry(plan.trajectory, config.odometry, report.clocks, mission.config.seed,
                        plan.id, (dir / "odometry.log").string(), report.odometry, error) ||
        !WriteTum(plan.trajectory, report.clocks, config.truth_rate_hz,
                  (dir / "ground_truth.tum").string()) ||
        !WriteStartPose(plan, (dir / "start_pose.txt").string())) {
      error = "robot " + std::to_string(plan.id) + ": " + (error.empty() ? "write failed" : error);
      return false;
    }
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - r0).count();
    const LidarSimStats& ls = report.lidar;
    const OdometrySimStats& os = report.odometry;
    std::printf("robot %d: start %s (%.2f, %.2f, %.0f deg) at %.1f s, %.0f m walked, rooms",
                plan.id, plan.start_room.c_str(), plan.start.x, plan.start.y,
                plan.start.yaw * 57.29577951308232, plan.start_delay_s, os.path_length_m);
    for (const auto& r : plan.rooms_visited) std::printf(" %s", r.c_str());
    int peeks = 0;
    for (const Visit& v : plan.visits) peeks += v.kind == VisitKind::kPeek ? 1 : 0;
    std::printf("; %zu visits (%d peeks)\n", plan.visits.size() - 1, peeks);
    std::printf(
        "  lidar: %llu packets, %.1f %% returns, %llu dropouts, %llu on people; odometry: %llu "
        "samples, %llu dropped, scale error %+.2f %%, yaw drift %+.2f deg/10 m, %zu slips; "
        "%.1f s\n",
        static_cast<unsigned long long>(ls.data_packets),
        100.0 * static_cast<double>(ls.returns) /
            static_cast<double>(std::max<std::uint64_t>(1, ls.rays)),
        static_cast<unsigned long long>(ls.dropouts),
        static_cast<unsigned long long>(ls.person_returns),
        static_cast<unsigned long long>(os.samples), static_cast<unsigned long long>(os.dropped),
        100.0 * os.scale_error, os.yaw_drift_rad_per_m * 10.0 * 57.29577951308232, os.slips.size(),
        seconds);
    std::fflush(stdout);
    reports.push_back(std::move(report));
  }
  for (std::size_t i = 0; i < mission.robots.size(); ++i) {
    RobotTruth t;
    t.id = mission.robots[i].id;
    t.trajectory = &mission.robots[i].trajectory;
    t.visibility = &visibility[i];
    for (const Visit& v : mission.robots[i].visits) {
      if (v.kind == VisitKind::kPeek) t.peeked.push_back(v.room);
    }
    truths.push_back(std::move(t));
  }
  MissionSettings settings;
  settings.truth_rate_hz = config.truth_rate_hz;
  settings.slip = config.odometry.slip.enabled;
  settings.start_delays = config.start_delays;
  if (!WriteVisibilityCsv(truths, (truth_dir / "visibility.csv").string()) ||
      !WriteSharedCsv(ComputeSharing(world, level, truths, config.shared_min_hits),
                      config.shared_min_hits, (truth_dir / "shared.csv").string()) ||
      !WriteMissionTxt(world, mission, settings, reports, (out / "mission.txt").string())) {
    error = "cannot write mission.txt or the visibility truth in " + out_dir;
    return false;
  }
  return true;
}

}  // namespace msgraphs::sim
