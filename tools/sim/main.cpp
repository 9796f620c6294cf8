// SPDX-License-Identifier: MIT
// msgraphs_sim: renders a multi-robot mission through a world into the recordings a real robot
// makes (VLP-16 pcap, CAN odometry candump log) plus ground truth. docs/simulator.md.
//
//   msgraphs_sim --world tools/sim/worlds/office.world --out runs/office --robots 3
//       --duration-s 300 --seed 1
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

#include "mission.hpp"
#include "mission_output.hpp"
#include "scene.hpp"
#include "truth.hpp"
#include "world.hpp"
#include "world_writer.hpp"

namespace {

using namespace msgraphs::sim;

void Usage() {
  std::fprintf(
      stderr,
      "usage: msgraphs_sim (--world FILE | --building SEED [building options])\n"
      "                    (--out DIR | --validate | --svg FILE)\n"
      "         [--robots N (1..10, default 3)] [--duration-s S (default 300)] [--seed N]\n"
      "         [--threads N] [--pcap-ns] [--svg FILE] [--shared-rooms N (default 2)]\n"
      "         [--visit-kinds peek=W,partial=W,full=W (default full=1)]\n"
      "         [--start-delays none|random|R=S,... (default none)] [--people N (default 0)]\n"
      "         [--truth-rate-hz R (10..1000, default 100)] [--slip on|off (default off)]\n"
      "         [--gait on|off (default on)]\n"
      "         [--benchmark: a benchmark mission's defaults (visit kinds\n"
      "          peek=0.3,partial=0.3,full=0.4, slips on, random start delays); the other\n"
      "          options, wherever they are, still apply]\n"
      "       msgraphs_sim --building SEED [building options] --world-out FILE [--svg FILE]\n"
      "building options: --style office|hospital|warehouse|construction|apartment|multi-wing\n"
      "         --corridor straight|L|T|U|loop  --symmetry none|identical-row|mirrored-wings|both\n"
      "         --clutter none|sparse|medium|dense  --rotation-deg D\n"
      "         --wing-angle-deg 0|30|45|60|90  --ceiling-m H (2.3..6)\n");
}

bool OnOff(const std::string& v, bool& out) {
  if (v != "on" && v != "off") return false;
  out = v == "on";
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  std::string world_path, out_dir, svg_path, world_out, error;
  std::optional<std::uint64_t> building_seed;
  msgraphs::sim::building::BuildingOptions building_options;
  bool validate_only = false;
  MissionConfig mission_config;
  OutputConfig output;
  output.lidar.threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  // A benchmark mission's defaults first: the other options override them.
  for (int i = 1; i < argc; ++i) {
    if (std::string(argv[i]) != "--benchmark") continue;
    mission_config.visit_kinds = VisitKinds::Benchmark();
    mission_config.start_delays.mode = StartDelays::Mode::kRandom;
    output.start_delays = "random";
    output.odometry.slip.enabled = true;
  }
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
    bool ok = true;
    if (a == "--world")
      world_path = need();
    else if (a == "--out")
      out_dir = need();
    else if (a == "--svg")
      svg_path = need();
    else if (a == "--validate")
      validate_only = true;
    else if (a == "--benchmark")
      continue;  // applied above
    else if (a == "--pcap-ns")
      output.lidar.nanosecond_pcap = true;
    else if (a == "--robots")
      mission_config.robots = std::atoi(need());
    else if (a == "--duration-s")
      mission_config.duration_s = std::atof(need());
    else if (a == "--seed")
      mission_config.seed = std::strtoull(need(), nullptr, 10);
    else if (a == "--threads")
      output.lidar.threads = std::max(1, std::atoi(need()));
    else if (a == "--shared-rooms")
      mission_config.shared_rooms = std::atoi(need());
    else if (a == "--people")
      mission_config.people.count = std::atoi(need());
    else if (a == "--truth-rate-hz")
      output.truth_rate_hz = std::atof(need());
    else if (a == "--slip")
      ok = OnOff(need(), output.odometry.slip.enabled);
    else if (a == "--gait")
      ok = OnOff(need(), mission_config.gait.enabled);
    else if (a == "--visit-kinds") {
      const auto kinds = VisitKinds::Parse(need(), error);
      ok = kinds.has_value();
      if (ok) mission_config.visit_kinds = *kinds;
    } else if (a == "--start-delays") {
      output.start_delays = need();
      const auto delays = StartDelays::Parse(output.start_delays, error);
      ok = delays.has_value();
      if (ok) mission_config.start_delays = *delays;
    }
    else if (a == "--building") {
      const char* text = need();
      char* end = nullptr;
      building_seed = std::strtoull(text, &end, 10);
      if (end == text || *end != '\0') {
        std::fprintf(stderr, "msgraphs_sim: --building needs a seed (a whole number), not '%s'\n",
                     text);
        return 2;
      }
    } else if (a == "--world-out") {
      world_out = need();
    } else if (msgraphs::sim::building::IsOption(a)) {
      ok = msgraphs::sim::building::SetOption(a, need(), building_options, error);
    } else {
      Usage();
      return 2;
    }
    if (!ok) {
      if (!error.empty()) std::fprintf(stderr, "msgraphs_sim: %s\n", error.c_str());
      Usage();
      return 2;
    }
  }
  if (world_path.empty() == !building_seed.has_value() || (!world_out.empty() && !building_seed) ||
      (out_dir.empty() && !validate_only && svg_path.empty() && world_out.empty())) {
    Usage();
    return 2;
  }
  if (!(output.truth_rate_hz >= 10.0 && output.truth_rate_hz <= 1000.0)) {
    std::fprintf(stderr, "msgraphs_sim: --truth-rate-hz must be 10..1000\n");
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
    output.world_path = world_path;
  }
  if (!world) {
    std::fprintf(stderr, "msgraphs_sim: %s\n", error.c_str());
    return 1;
  }
  std::printf("world: %s (%s): %zu walls, %zu rooms, %zu boxes, %zu cylinders, %zu level(s)\n",
              world_path.c_str(), world->name.c_str(), world->walls.size(), world->rooms.size(),
              world->boxes.size(), world->cylinders.size(), world->levels.size());
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
  if (!WriteMissionOutputs(*world, scene, *mission, output, out_dir, error)) {
    std::fprintf(stderr, "msgraphs_sim: %s\n", error.c_str());
    return 1;
  }
  if (building_seed) {  // the generated world and its feature summary beside the recordings
    if (!SaveWorld(*world, (fs::path(out_dir) / "world.world").string()) ||
        !(std::ofstream(fs::path(out_dir) / "building.txt") << building_text)) {
      std::fprintf(stderr, "msgraphs_sim: cannot write the building into %s\n", out_dir.c_str());
      return 1;
    }
  }
  const double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("rendered %d robots x %.0f s in %.1f s (%d threads) into %s\n", mission_config.robots,
              mission_config.duration_s, total, output.lidar.threads, out_dir.c_str());
  return 0;
}
