// SPDX-License-Identifier: MIT
// msgraphs_sim: renders a multi-robot mission through a world into the recordings a real robot
// makes (VLP-16 pcap, CAN odometry candump log) plus ground truth. docs/simulator.md.
//
//   msgraphs_sim --world tools/sim/worlds/office.world --out runs/office --robots 3 --duration-s 300 --seed 1
//   msgraphs_sim --world my.world --validate          # check a world file and stop
//   msgraphs_sim --building 7 --out runs/b7           # a generated building (building/generate.hpp)
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <thread>

#include "building/generate.hpp"

#include "lidar_sim.hpp"
#include "mission.hpp"
#include "odometry_sim.hpp"
#include "scene.hpp"
#include "truth.hpp"
#include "world.hpp"
#include "world_writer.hpp"

namespace {

using namespace msgraphs::sim;

void Usage() {
  std::fprintf(stderr,
               "usage: msgraphs_sim (--world FILE | --building SEED [building options]) (--out DIR | --validate | --svg FILE)\n"
               "                    [--robots N (2..10, default 3)] [--duration-s S (default 300)] [--seed N]\n"
               "                    [--threads N] [--pcap-ns] [--svg FILE] [--shared-rooms N (default 2)]\n"
               "       msgraphs_sim --building SEED [building options] --world-out FILE [--svg FILE]\n"
               "building options: --style office|hospital|warehouse|construction|apartment|multi-wing\n"
               "                  --corridor straight|L|T|U|loop  --symmetry none|identical-row|mirrored-wings|both\n"
               "                  --clutter none|sparse|medium|dense  --rotation-deg D  --wing-angle-deg 0|30|45|60|90\n"
               "                  --ceiling-m H (2.3..6)\n");
}

}  // namespace

int main(int argc, char** argv) {
  std::string world_path, out_dir, svg_path, world_out, error;
  std::optional<std::uint64_t> building_seed;
  msgraphs::sim::building::BuildingOptions building_options;
  bool validate_only = false, pcap_ns = false;
  MissionConfig mission_config;
  int threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const char* v = i + 1 < argc ? argv[i + 1] : nullptr;
    auto need = [&]() -> const char* {
      if (v == nullptr) {
        Usage();
        std::exit(2);
      }
      ++i;
      return v;
    };
    if (a == "--world") world_path = need();
    else if (a == "--out") out_dir = need();
    else if (a == "--svg") svg_path = need();
    else if (a == "--validate") validate_only = true;
    else if (a == "--pcap-ns") pcap_ns = true;
    else if (a == "--robots") mission_config.robots = std::atoi(need());
    else if (a == "--duration-s") mission_config.duration_s = std::atof(need());
    else if (a == "--seed") mission_config.seed = std::strtoull(need(), nullptr, 10);
    else if (a == "--threads") threads = std::max(1, std::atoi(need()));
    else if (a == "--shared-rooms") mission_config.shared_rooms = std::atoi(need());
    else if (a == "--building") {
      const char* text = need();
      char* end = nullptr;
      building_seed = std::strtoull(text, &end, 10);
      if (end == text || *end != '\0') {
        std::fprintf(stderr, "msgraphs_sim: --building needs a seed (a whole number), not '%s'\n", text);
        return 2;
      }
    }
    else if (a == "--world-out") world_out = need();
    else if (msgraphs::sim::building::IsOption(a)) {
      if (!msgraphs::sim::building::SetOption(a, need(), building_options, error)) {
        std::fprintf(stderr, "msgraphs_sim: %s\n", error.c_str());
        return 2;
      }
    } else {
      Usage();
      return 2;
    }
  }
  if (world_path.empty() == !building_seed.has_value() || (!world_out.empty() && !building_seed) ||
      (out_dir.empty() && !validate_only && svg_path.empty() && world_out.empty())) {
    Usage();
    return 2;
  }
  std::optional<World> world;
  std::string building_text;  // the generated building's feature summary
  if (building_seed) {
    if (const std::string e = msgraphs::sim::building::CheckOptions(building_options); !e.empty()) {
      std::fprintf(stderr, "msgraphs_sim: %s\n", e.c_str());
      return 2;
    }
    msgraphs::sim::building::BuildingFeatures features;
    world = msgraphs::sim::building::GenerateBuilding(*building_seed, building_options, &features);
    building_text = msgraphs::sim::building::WriteFeatures(features);
    world_path = "building " + std::to_string(*building_seed);
    if (!world_out.empty()) {
      const std::string summary = std::filesystem::path(world_out).replace_extension(".building.txt").string();
      if (!SaveWorld(*world, world_out) || !(std::ofstream(summary) << building_text) ||
          (!svg_path.empty() && out_dir.empty() && !WriteSvg(*world, nullptr, 0, svg_path))) {
        std::fprintf(stderr, "msgraphs_sim: cannot write %s\n", world_out.c_str());
        return 1;
      }
      if (out_dir.empty()) return 0;
    }
  } else {
    world = LoadWorld(world_path, error);
  }
  if (!world) {
    std::fprintf(stderr, "msgraphs_sim: %s\n", error.c_str());
    return 1;
  }
  std::printf("world: %s (%s): %zu walls, %zu rooms, %zu boxes, %zu cylinders, %zu level(s)\n", world_path.c_str(),
              world->name.c_str(), world->walls.size(), world->rooms.size(), world->boxes.size(),
              world->cylinders.size(), world->levels.size());
  std::fflush(stdout);
  if (validate_only) return 0;
  if (mission_config.robots < 1 || mission_config.robots > 10) {
    std::fprintf(stderr, "msgraphs_sim: --robots must be 1..10\n");
    return 2;
  }

  const auto t0 = std::chrono::steady_clock::now();
  const Scene scene(*world, mission_config.level);
  auto mission = PlanMission(*world, scene, mission_config, error);
  if (!mission) {
    std::fprintf(stderr, "msgraphs_sim: mission: %s\n", error.c_str());
    return 1;
  }
  if (!svg_path.empty() && !WriteSvg(*world, &*mission, mission_config.level, svg_path)) {
    std::fprintf(stderr, "msgraphs_sim: cannot write %s\n", svg_path.c_str());
    return 1;
  }
  if (out_dir.empty()) return 0;

  namespace fs = std::filesystem;
  fs::create_directories(fs::path(out_dir) / "truth");
  if (building_seed) {
    SaveWorld(*world, (fs::path(out_dir) / "world.world").string());
    std::ofstream(fs::path(out_dir) / "building.txt") << building_text;
  } else {
    fs::copy_file(world_path, fs::path(out_dir) / "world.world", fs::copy_options::overwrite_existing);
  }
  WriteWallsCsv(*world, (fs::path(out_dir) / "truth" / "walls.csv").string());
  WriteRoomsCsv(*world, (fs::path(out_dir) / "truth" / "rooms.csv").string());
  WriteSvg(*world, &*mission, mission_config.level, (fs::path(out_dir) / "map.svg").string());

  std::ofstream summary(fs::path(out_dir) / "mission.txt");
  summary << "msgraphs-mission 1\nworld " << world->name << "\nseed " << mission_config.seed << "\nduration_s "
          << mission_config.duration_s << "\nrobots " << mission_config.robots << "\nshared_rooms";
  for (const auto& r : mission->shared_rooms) summary << " " << r;
  summary << "\n";

  LidarSimConfig lidar;
  lidar.nanosecond_pcap = pcap_ns;
  lidar.threads = threads;
  OdometrySimConfig odometry;
  for (const RobotPlan& plan : mission->robots) {
    const fs::path dir = fs::path(out_dir) / ("robot" + std::to_string(plan.id));
    fs::create_directories(dir);
    const RobotClocks clocks = RobotClocks::Draw(mission_config.seed, plan.id);
    LidarSimStats ls;
    OdometrySimStats os;
    const auto r0 = std::chrono::steady_clock::now();
    if (!RenderLidar(scene, plan.trajectory, lidar, clocks, mission_config.seed, plan.id,
                     (dir / "velodyne.pcap").string(), ls, error) ||
        !RenderOdometry(plan.trajectory, odometry, clocks, mission_config.seed, plan.id,
                        (dir / "odometry.log").string(), os, error) ||
        !WriteTum(plan.trajectory, clocks, 100.0, (dir / "ground_truth.tum").string()) ||
        !WriteStartPose(plan, plan.trajectory.base_z_m(), (dir / "start_pose.txt").string())) {
      std::fprintf(stderr, "msgraphs_sim: robot %d: %s\n", plan.id, error.empty() ? "write failed" : error.c_str());
      return 1;
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - r0).count();
    std::printf("robot %d: start %s (%.2f, %.2f, %.0f deg), %.0f m walked, rooms", plan.id, plan.start_room.c_str(),
                plan.start.x, plan.start.y, plan.start.yaw * 57.29577951308232, os.path_length_m);
    for (const auto& r : plan.rooms_visited) std::printf(" %s", r.c_str());
    std::printf("\n  lidar: %llu packets, %.1f %% returns, %llu dropouts; odometry: %llu samples, %llu dropped, "
                "scale error %+.2f %%, yaw drift %+.2f deg/10 m; %.1f s\n",
                static_cast<unsigned long long>(ls.data_packets), 100.0 * static_cast<double>(ls.returns) / static_cast<double>(ls.rays),
                static_cast<unsigned long long>(ls.dropouts), static_cast<unsigned long long>(os.samples),
                static_cast<unsigned long long>(os.dropped), 100.0 * os.scale_error,
                os.yaw_drift_rad_per_m * 10.0 * 57.29577951308232, seconds);
    summary << "robot " << plan.id << " start_room " << plan.start_room << " unix_offset_s "
            << std::to_string(clocks.unix_offset_s) << " scale_error " << os.scale_error << " yaw_drift_rad_per_m "
            << os.yaw_drift_rad_per_m << " dropped_samples " << os.dropped << " path_m " << os.path_length_m
            << " rooms";
    for (const auto& r : plan.rooms_visited) summary << " " << r;
    summary << "\n";
  }
  const double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("rendered %d robots x %.0f s in %.1f s (%d threads) into %s\n", mission_config.robots,
              mission_config.duration_s, total, threads, out_dir.c_str());
  return 0;
}
