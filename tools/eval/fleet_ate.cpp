// SPDX-License-Identifier: MIT
// msgraphs_fleet_ate: how well a fleet of msgraphs_node processes placed each other, from
// their output folders. For every robot V (the view), every robot that V merged is brought into
// V's map frame through V's origins.csv, with its own keyframes.tum; the aggregated trajectory
// is aligned to the ground truth once (SE(3)) and its ATE printed, with each merged origin's
// error against the truth. Every keyframe is paired with its own robot's truth interpolated at
// its stamp (tools/truth_pairing.hpp); every robot is listed, and one without (enough) paired
// keyframes is reported with the reason and fails the run, never left out of a figure.
//
//   msgraphs_fleet_ate --run RUN --out OUT [--expect-merged] [--max-ate-m X]
//
// RUN/robotK/ground_truth.tum (the simulator's), OUT/robotK/{keyframes.tum,origins.csv} (the
// nodes'). A robot is in the fleet when either folder has it. Exit 1 when a robot's own ATE
// cannot be computed, a merged robot cannot be scored in a view, --expect-merged and a view did
// not merge every robot, or an aggregated ATE is above --max-ate-m.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "msgraphs/tools/aggregated_ate.hpp"
#include "msgraphs/tools/ate.hpp"
#include "msgraphs/tools/truth_pairing.hpp"
#include "msgraphs/tools/tum.hpp"

namespace {

namespace fs = std::filesystem;
using msgraphs::tools::StampedPose;
using msgraphs::tools::TruthTrajectory;

struct Origin {
  bool merged = false;
  Eigen::Isometry3d T_view_robot = Eigen::Isometry3d::Identity();
};

std::map<int, Origin> ReadOrigins(const fs::path& path) {
  std::map<int, Origin> out;
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);  // header
  while (std::getline(in, line)) {
    std::replace(line.begin(), line.end(), ',', ' ');
    std::istringstream s(line);
    int robot = 0, merged = 0;
    double x, y, z, qx, qy, qz, qw;
    if (!(s >> robot >> merged >> x >> y >> z >> qx >> qy >> qz >> qw)) continue;
    Origin o;
    o.merged = merged != 0;
    o.T_view_robot.linear() = Eigen::Quaterniond(qw, qx, qy, qz).normalized().toRotationMatrix();
    o.T_view_robot.translation() << x, y, z;
    out[robot] = o;
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  std::string run, out;
  bool expect_merged = false;
  double max_ate_m = 0;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--run" && i + 1 < argc)
      run = argv[++i];
    else if (a == "--out" && i + 1 < argc)
      out = argv[++i];
    else if (a == "--expect-merged")
      expect_merged = true;
    else if (a == "--max-ate-m" && i + 1 < argc)
      max_ate_m = std::atof(argv[++i]);
    else {
      std::fprintf(
          stderr,
          "usage: msgraphs_fleet_ate --run RUN --out OUT [--expect-merged] [--max-ate-m X]\n");
      return 2;
    }
  }
  // The fleet: every robot with a node output folder or a truth, so that none drops out.
  std::map<int, std::vector<StampedPose>> keyframes;
  std::map<int, TruthTrajectory> truth;
  std::vector<int> fleet;
  for (int k = 1; k <= 64; ++k) {
    const fs::path kf = fs::path(out) / ("robot" + std::to_string(k)) / "keyframes.tum";
    const fs::path gt = fs::path(run) / ("robot" + std::to_string(k)) / "ground_truth.tum";
    const bool have_kf = fs::exists(kf), have_gt = fs::exists(gt);
    if (!have_kf && !have_gt && !fs::exists(kf.parent_path())) continue;
    fleet.push_back(k);
    if (have_kf) keyframes[k] = msgraphs::tools::ReadTum(kf.string());
    if (have_gt) truth.emplace(k, TruthTrajectory(msgraphs::tools::ReadTum(gt.string())));
  }
  if (keyframes.size() < 2) {
    std::fprintf(stderr, "fleet_ate: fewer than two robots with keyframes.tum in %s\n",
                 out.c_str());
    return 1;
  }
  int failures = 0;
  std::map<int, Eigen::Isometry3d> T_world_map;  // each robot's own alignment to the truth
  for (int k : fleet) {
    if (!keyframes.count(k)) {
      std::printf("robot %d alone: FAILED: no keyframes.tum\n", k);
      ++failures;
      continue;
    }
    if (!truth.count(k)) {
      std::printf("robot %d alone: FAILED: no ground_truth.tum (%zu keyframes)\n", k,
                  keyframes[k].size());
      ++failures;
      continue;
    }
    const auto own = msgraphs::tools::ComputeAte(keyframes[k], truth.at(k));
    if (!own.ok) {
      std::printf("robot %d alone: ATE FAILED: %s; %zu of %zu keyframes paired (unpaired: %s)\n", k,
                  own.error, own.pairs.paired, keyframes[k].size(),
                  own.pairs.DescribeUnpaired().c_str());
      ++failures;
      continue;
    }
    T_world_map[k] = own.T_truth_estimate;
    std::printf("robot %d alone: ATE %.3f m over %zu keyframes (unpaired: %s)\n", k, own.rmse,
                own.poses(), own.pairs.DescribeUnpaired().c_str());
  }
  for (const auto& [view, own_keyframes] : keyframes) {
    const auto origins =
        ReadOrigins(fs::path(out) / ("robot" + std::to_string(view)) / "origins.csv");
    msgraphs::tools::AggregatedAteBuilder builder;
    std::size_t merged = 0;
    std::string origin_errors;
    for (int robot : fleet) {
      const TruthTrajectory* robot_truth = truth.count(robot) ? &truth.at(robot) : nullptr;
      if (robot == view) {
        ++merged;
        builder.AddMerged(robot, own_keyframes, robot_truth);
        continue;
      }
      auto it = origins.find(robot);
      if (it == origins.end() || !it->second.merged) {
        builder.AddNotMerged(robot);
        continue;
      }
      if (!keyframes.count(robot)) {
        // Merged by the view, yet no keyframes to bring into its frame: the view cannot be scored.
        builder.AddMerged(robot, {}, robot_truth);
        ++merged;
        continue;
      }
      ++merged;
      const Eigen::Isometry3d& T = it->second.T_view_robot;
      char buffer[160];
      if (T_world_map.count(view) && T_world_map.count(robot)) {
        const Eigen::Isometry3d T_true = T_world_map[view].inverse() * T_world_map[robot];
        const Eigen::Isometry3d e = T_true.inverse() * T;
        std::snprintf(buffer, sizeof buffer, "; origin of robot %d off by %.3f m, %.2f deg", robot,
                      e.translation().norm(), Eigen::AngleAxisd(e.linear()).angle() * 180.0 / M_PI);
      } else {
        std::snprintf(buffer, sizeof buffer,
                      "; origin of robot %d not checked (no truth alignment of robot %d)", robot,
                      T_world_map.count(view) ? robot : view);
        ++failures;
      }
      origin_errors += buffer;
      std::vector<StampedPose> in_view;
      for (const StampedPose& p : keyframes[robot]) in_view.push_back({p.t, T * p.T});
      builder.AddMerged(robot, in_view, robot_truth);
    }
    const msgraphs::tools::AggregatedAte ate = builder.Finish();
    if (ate.ok()) {
      std::printf(
          "view of robot %d: merged %zu of %zu robots; aggregated ATE %.3f m over %zu keyframes "
          "(%s)%s\n",
          view, merged, fleet.size(), ate.ate.rmse, ate.ate.poses(), ate.Describe().c_str(),
          origin_errors.c_str());
    } else {
      std::printf("view of robot %d: merged %zu of %zu robots; aggregated ATE FAILED: %s (%s)%s\n",
                  view, merged, fleet.size(), ate.failure().c_str(), ate.Describe().c_str(),
                  origin_errors.c_str());
      ++failures;
    }
    if (expect_merged && merged != fleet.size()) ++failures;
    if (max_ate_m > 0 && !(ate.ok() && ate.ate.rmse <= max_ate_m)) ++failures;
  }
  return failures == 0 ? 0 : 1;
}
