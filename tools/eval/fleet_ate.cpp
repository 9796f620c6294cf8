// SPDX-License-Identifier: MIT
// msgraphs_fleet_ate: how well a fleet of msgraphs_node processes placed each other, from
// their output folders. For every robot V (the view), every robot that V merged is brought into
// V's map frame through V's origins.csv, with its own keyframes.tum; the aggregated trajectory
// is aligned to the ground truth once (SE(3)) and its ATE printed, with each merged origin's
// error against the truth.
//
//   msgraphs_fleet_ate --run RUN --out OUT [--expect-merged] [--max-ate-m X]
//
// RUN/robotK/ground_truth.tum (the simulator's), OUT/robotK/{keyframes.tum,origins.csv} (the
// nodes'). Exit 1 when --expect-merged and a view did not merge every robot, or an aggregated
// ATE is above --max-ate-m.
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

#include "msgraphs/tools/tum.hpp"

namespace {

namespace fs = std::filesystem;
using msgraphs::tools::StampedPose;

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
  std::map<int, std::vector<StampedPose>> keyframes, truth;
  std::map<int, Eigen::Isometry3d> T_world_map;  // each robot's own alignment to the truth
  for (int k = 1; k <= 64; ++k) {
    const fs::path kf = fs::path(out) / ("robot" + std::to_string(k)) / "keyframes.tum";
    const fs::path gt = fs::path(run) / ("robot" + std::to_string(k)) / "ground_truth.tum";
    if (!fs::exists(kf) || !fs::exists(gt)) continue;
    keyframes[k] = msgraphs::tools::ReadTum(kf.string());
    truth[k] = msgraphs::tools::ReadTum(gt.string());
    const auto own = msgraphs::tools::ComputeAte(keyframes[k], truth[k], 0.006);
    if (!own.ok) {
      std::fprintf(stderr, "fleet_ate: robot %d: %s\n", k, own.error);
      return 1;
    }
    T_world_map[k] = own.T_truth_estimate;
    std::printf("robot %d alone: ATE %.3f m over %zu keyframes\n", k, own.rmse, own.poses);
  }
  if (keyframes.size() < 2) {
    std::fprintf(stderr, "fleet_ate: fewer than two robots with keyframes.tum in %s\n",
                 out.c_str());
    return 1;
  }
  int failures = 0;
  for (const auto& [view, own_keyframes] : keyframes) {
    const auto origins =
        ReadOrigins(fs::path(out) / ("robot" + std::to_string(view)) / "origins.csv");
    std::vector<StampedPose> aggregated, aggregated_truth;
    std::size_t merged = 1;
    std::string origin_errors;
    for (const auto& [robot, poses] : keyframes) {
      Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
      if (robot != view) {
        auto it = origins.find(robot);
        if (it == origins.end() || !it->second.merged) continue;
        ++merged;
        T = it->second.T_view_robot;
        const Eigen::Isometry3d T_true = T_world_map[view].inverse() * T_world_map[robot];
        const Eigen::Isometry3d e = T_true.inverse() * T;
        char buffer[128];
        std::snprintf(buffer, sizeof buffer, "; origin of robot %d off by %.3f m, %.2f deg", robot,
                      e.translation().norm(), Eigen::AngleAxisd(e.linear()).angle() * 180.0 / M_PI);
        origin_errors += buffer;
      }
      for (const StampedPose& p : poses) {
        // Robots' stamps overlap: pair each keyframe with its own robot's truth here.
        if (const StampedPose* t = msgraphs::tools::Nearest(truth[robot], p.t, 0.006)) {
          const double stamp = static_cast<double>(aggregated.size());
          aggregated.push_back({stamp, T * p.T});
          aggregated_truth.push_back({stamp, t->T});
        }
      }
    }
    const auto ate = msgraphs::tools::ComputeAte(aggregated, aggregated_truth, 0.5);
    std::printf(
        "view of robot %d: merged %zu of %zu robots; aggregated ATE %.3f m over %zu keyframes%s\n",
        view, merged, keyframes.size(), ate.rmse, ate.poses, origin_errors.c_str());
    if (expect_merged && merged != keyframes.size()) ++failures;
    if (max_ate_m > 0 && !(ate.ok && ate.rmse <= max_ate_m)) ++failures;
  }
  return failures == 0 ? 0 : 1;
}
