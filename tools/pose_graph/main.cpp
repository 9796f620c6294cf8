// SPDX-License-Identifier: MIT
// msgraphs_pose_graph: optimises a g2o pose graph and reports the SE-Sync objective, so results
// can be compared with published optima (docs/pose-graph.md).
//
//   msgraphs_pose_graph --in intel.g2o [--out solved.g2o] [--cost chordal|geodesic]
//                       [--init chordal|tree|given]
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "msgraphs/core/graph/pose_graph_optimizer.hpp"

int main(int argc, char** argv) {
  using namespace msgraphs::core;
  std::string in, out;
  PoseGraphSolverConfig config;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const std::string v = i + 1 < argc ? argv[i + 1] : "";
    if (a == "--in") in = v, ++i;
    else if (a == "--out") out = v, ++i;
    else if (a == "--cost" && (v == "chordal" || v == "geodesic")) {
      config.cost = v == "chordal" ? PoseGraphCost::kChordal : PoseGraphCost::kGeodesic;
      ++i;
    } else if (a == "--init" && (v == "chordal" || v == "tree" || v == "given")) {
      config.initialisation = v == "chordal" ? PoseGraphInitialisation::kChordal
                              : v == "tree"  ? PoseGraphInitialisation::kSpanningTree
                                             : PoseGraphInitialisation::kAsGiven;
      ++i;
    } else {
      std::fprintf(stderr, "usage: msgraphs_pose_graph --in FILE.g2o [--out FILE.g2o] [--cost chordal|geodesic] [--init chordal|tree|given]\n");
      return 2;
    }
  }
  std::ifstream file(in);
  if (!file) {
    std::fprintf(stderr, "pose_graph: cannot open %s\n", in.c_str());
    return 1;
  }
  std::stringstream text;
  text << file.rdbuf();
  std::string detail;
  auto graph = ParseG2o(text.str(), &detail);
  if (!graph) {
    std::fprintf(stderr, "pose_graph: %s: %s\n", in.c_str(), detail.c_str());
    return 1;
  }
  const auto t0 = std::chrono::steady_clock::now();
  auto report = OptimizePoseGraph(*graph, config);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!report) {
    std::fprintf(stderr, "pose_graph: %s\n", report.error().detail);
    return 1;
  }
  std::printf("%s: %zu poses, %zu edges (%s); SE-Sync objective %.6g after initialisation, %.6g at the solution; "
              "%d iterations, %s; %.2f s (final solve %.2f s)\n",
              in.c_str(), graph->poses.size(), graph->edges.size(), graph->planar ? "SE2" : "SE3",
              report->initial_objective, report->final_objective, report->iterations,
              report->converged ? "converged" : "not converged", seconds, report->solver_seconds);
  if (std::getenv("MSGRAPHS_VERBOSE") != nullptr) std::printf("%s\n", report->solver_report.c_str());
  if (!out.empty()) {
    std::ofstream o(out);
    o << WriteG2o(*graph);
  }
  return 0;
}
