// SPDX-License-Identifier: MIT
// The pose-graph backbone: g2o parsing and writing, the SE-Sync objective, chordal
// initialisation, optimisation; on the public benchmarks (label external) the SE-Sync objective
// reached against the published optima (within 1e-3 relative), and MRPT's input/expected pairs.
#include <gtest/gtest.h>

#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>

#include "msgraphs/core/graph/pose_graph_optimizer.hpp"
#include "test_data.hpp"

namespace msgraphs::core {
namespace {

std::string Slurp(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

#ifndef MSGRAPHS_BENCHMARKS_ONLY  // the slow binary runs only the large public graphs
TEST(PoseGraph, ParsesWritesAndRejectsBadLines) {
  const std::string text =
      "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0.5\nFIX 0\n# comment\n"
      "EDGE_SE2 0 1 1 0 0.5 10 0 0 10 0 100\n";
  auto g = ParseG2o(text);
  ASSERT_TRUE(g.has_value());
  EXPECT_TRUE(g->planar);
  ASSERT_EQ(g->poses.size(), 2u);
  EXPECT_EQ(g->fixed.size(), 1u);
  EXPECT_NEAR(g->edges[0].information(5, 5), 100.0, 1e-12);
  auto again = ParseG2o(WriteG2o(*g));
  ASSERT_TRUE(again.has_value());
  EXPECT_TRUE(again->poses[1].isApprox(g->poses[1]));
  EXPECT_NEAR(SeSyncObjective(*g), 0.0, 1e-12) << "the poses agree with the edge exactly";

  std::string detail;
  for (const char* bad : {"EDGE_SE2 0 1 1 0 0.5 10 0 0 10 0\n", "VERTEX_SE2 0 0 nan 0\n", "POINT 1 2 3\n",
                          "EDGE_SE2 0 0 1 0 0 1 0 0 1 0 1\n", "EDGE_SE2 0 1 1 0 0 0 0 0 0 0 0\n",
                          "VERTEX_SE3:QUAT 0 0 0 0 0 0 0 2\n", "VERTEX_SE2 -1 0 0 0\n"}) {
    EXPECT_FALSE(ParseG2o(bad, &detail).has_value()) << bad;
    EXPECT_NE(detail.find("line 1"), std::string::npos) << detail;
  }
  EXPECT_EQ(ParseG2o("VERTEX_SE2 0 0 0 0\nVERTEX_SE3:QUAT 1 0 0 0 0 0 0 1\n").error().code, Errc::kUnsupported);
}

TEST(PoseGraph, ASquareWithANoisyClosureIsSolvedAndDisconnectedGraphsAreRefused) {
  // Four 1 m sides turning 90 degrees, the closure measured 10 cm and 3 degrees off.
  std::string text;
  for (int i = 0; i < 4; ++i) text += "VERTEX_SE2 " + std::to_string(i) + " 0 0 0\n";
  text += "EDGE_SE2 0 1 1 0 1.5707963 100 0 0 100 0 1000\nEDGE_SE2 1 2 1 0 1.5707963 100 0 0 100 0 1000\n";
  text += "EDGE_SE2 2 3 1 0 1.5707963 100 0 0 100 0 1000\nEDGE_SE2 3 0 1.1 0 1.62 100 0 0 100 0 1000\n";
  auto g = ParseG2o(text).value();
  auto r = OptimizePoseGraph(g, {});
  ASSERT_TRUE(r.has_value()) << r.error().detail;
  EXPECT_TRUE(r->converged);
  EXPECT_LT(r->final_objective, r->initial_objective + 1e-12);
  EXPECT_NEAR(g.poses[2].translation().x(), 1.0, 0.05);
  EXPECT_NEAR(g.poses[2].translation().y(), 1.0, 0.05);
  // Vertex 2 of 4 with only an edge 0-1: not connected.
  auto lonely = ParseG2o("VERTEX_SE2 0 0 0 0\nVERTEX_SE2 2 0 0 0\nEDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\n").value();
  EXPECT_EQ(OptimizePoseGraph(lonely, {}).error().code, Errc::kDegenerate);
}

#endif

struct Benchmark {
  const char* file;
  double optimum;  ///< SE-Sync IJRR 2019, Tables 1 and 2 (4 significant digits)
};

class SeSyncBenchmarks : public ::testing::TestWithParam<Benchmark> {};

TEST_P(SeSyncBenchmarks, ReachTheCertifiedOptimumWithin1e3) {
  std::filesystem::path path;
  MSGRAPHS_REQUIRE_DATA(std::string("g2o/") + GetParam().file, path);
  std::string detail;
  auto g = ParseG2o(Slurp(path), &detail);
  ASSERT_TRUE(g.has_value()) << detail;
  auto r = OptimizePoseGraph(*g, {});  // chordal initialisation, SE-Sync's objective
  ASSERT_TRUE(r.has_value()) << r.error().detail;
  const double relative = (r->final_objective - GetParam().optimum) / GetParam().optimum;
  RecordProperty("objective", std::to_string(r->final_objective));
  RecordProperty("initial_objective", std::to_string(r->initial_objective));
  RecordProperty("seconds", std::to_string(r->solver_seconds));
  // The published optima have 4 significant digits: half a unit in the last place is 5e-4.
  EXPECT_LT(std::fabs(relative), 1e-3) << r->final_objective << " vs " << GetParam().optimum;
}

INSTANTIATE_TEST_SUITE_P(Public, SeSyncBenchmarks,
                         ::testing::Values(MSGRAPHS_SESYNC_CASES),
                         [](const auto& test_info) {
                           std::string name = test_info.param.file;
                           for (char& c : name) {
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           }
                           return name;
                         });


#ifndef MSGRAPHS_BENCHMARKS_ONLY
struct MrptPair {
  const char* input;
  const char* expected;
  double tolerance;  ///< MRPT's: sum |pose difference| < 1e-3
};

class MrptPairs : public ::testing::TestWithParam<MrptPair> {};

// MRPT's graph-SLAM unit tests: optimise the input (g2o chi^2, given initial poses, FIX vertex as
// the gauge) and compare every pose with the expected output.
TEST_P(MrptPairs, MatchTheExpectedOutput) {
  std::filesystem::path in, out;
  MSGRAPHS_REQUIRE_DATA(std::string("g2o/mrpt_tests/") + GetParam().input, in);
  MSGRAPHS_REQUIRE_DATA(std::string("g2o/mrpt_tests/") + GetParam().expected, out);
  auto graph = ParseG2o(Slurp(in)).value();
  const auto expected = ParseG2o(Slurp(out)).value();
  PoseGraphSolverConfig config;
  config.cost = PoseGraphCost::kGeodesic;
  config.initialisation = PoseGraphInitialisation::kAsGiven;
  auto r = OptimizePoseGraph(graph, config);
  ASSERT_TRUE(r.has_value()) << r.error().detail;
  ASSERT_EQ(graph.poses.size(), expected.poses.size());
  double sum = 0;
  for (std::size_t i = 0; i < graph.poses.size(); ++i) {
    const Eigen::Isometry3d& a = graph.poses[i];
    const Eigen::Isometry3d& b = expected.poses[i];
    sum += (a.translation() - b.translation()).cwiseAbs().sum();
    if (graph.planar) {
      sum += std::fabs(std::remainder(std::atan2(a.linear()(1, 0), a.linear()(0, 0)) - std::atan2(b.linear()(1, 0), b.linear()(0, 0)),
                                      2 * std::numbers::pi));
    } else {
      Eigen::Quaterniond qa(a.linear()), qb(b.linear());
      if (qa.dot(qb) < 0) qa.coeffs() = -qa.coeffs();
      sum += (qa.coeffs() - qb.coeffs()).cwiseAbs().sum();
    }
  }
  RecordProperty("sum_abs_difference", std::to_string(sum));
  EXPECT_LT(sum, GetParam().tolerance);
  // Never worse than the expected output by the objective either.
  EXPECT_LE(r->final_objective, SeSyncObjective(expected) + 1e-9);
}

INSTANTIATE_TEST_SUITE_P(
    Mrpt, MrptPairs,
    ::testing::Values(MrptPair{"graphslam_SE2_in.graph", "graphslam_SE2_out_good.graph", 1e-3},
                      MrptPair{"graphslam_SE2_in2.graph", "graphslam_SE2_out_good2.graph", 1e-3},
                      MrptPair{"graphslam_SE2_in3.graph", "graphslam_SE2_out_good3.graph", 1e-3},
                      // MRPT's expected output stops at objective 1.3e-7; we reach 3.9e-10 (from its
                      // input or from its output alike), 1.6e-3 away in summed pose differences.
                      MrptPair{"graphslam_SE2pdf_in.graph", "graphslam_SE2pdf_out_good.graph", 2e-3},
                      MrptPair{"graphslam_SE3_in_torus3D-first100.graph", "graphslam_SE3_out_good_torus3D-first100.graph", 1e-3}));
#endif

}  // namespace
}  // namespace msgraphs::core
