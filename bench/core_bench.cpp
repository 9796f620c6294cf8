// SPDX-License-Identifier: MIT
// Core perception benchmarks, single thread:
//   MSGRAPHS_DATA_DIR=../shared/data build/host-release/bench/msgraphs_core_bench
// Goals (docs/performance.md): Scan Context build for a 30k-point room cloud <= 1 ms, a query over
// 1,000 stored rooms <= 0.1 ms, wall extraction per keyframe <= 20 ms; VGICP on the fast_gicp
// pair at 0.25 m next to the published single-thread anchors (32-40 ms per KITTI scan).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "../tests/core/synthetic_clouds.hpp"
#include "../tests/support/cloud_files.hpp"
#include "msgraphs/core/descriptors/scan_context.hpp"
#include "msgraphs/core/perception/covariances.hpp"
#include "msgraphs/core/perception/plane_extraction.hpp"
#include "msgraphs/core/perception/voxel_grid.hpp"
#include "msgraphs/core/registration/vgicp.hpp"

namespace {

using namespace msgraphs;
using namespace msgraphs::core;

std::vector<Eigen::Vector3f> RoomCloud(std::uint32_t seed, std::size_t n = 30000) {
  return test::BoxRoom(7, 5, 3, n, 0.02, seed, Eigen::Isometry3d(Eigen::Translation3d(-3.5, -2.5, 0)), false);
}

void BM_ScanContextBuild30k(benchmark::State& state) {
  const auto cloud = RoomCloud(1);
  ScanContext sc;
  for (auto _ : state) benchmark::DoNotOptimize(sc.Build(cloud, {}));
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(cloud.size()));
}
BENCHMARK(BM_ScanContextBuild30k)->Unit(benchmark::kMicrosecond);

// The room matcher's comparison (collab_room_matching.cpp): one own room against 100 peer rooms,
// every shift searched (rooms are nearly symmetric), as a peer's descriptors arrive.
void BM_ScanContextCompare100(benchmark::State& state) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> h(0.0f, 3.0f);
  std::vector<float> cells(1200);
  std::vector<ScanContext> peers(100);
  for (ScanContext& sc : peers) {
    for (auto& c : cells) c = h(rng);
    static_cast<void>(sc.FromCells(20, 60, 12.0f, cells));
  }
  ScanContext mine;
  static_cast<void>(mine.Build(RoomCloud(2), {}));
  for (auto _ : state) {
    float best = 2.0f;
    for (const ScanContext& peer : peers) {
      const auto match = ScanContextDistance(mine, peer, true);
      if (match) best = std::min(best, match->distance);
    }
    benchmark::DoNotOptimize(best);
  }
}
BENCHMARK(BM_ScanContextCompare100)->Unit(benchmark::kMicrosecond);

// A keyframe as the front end makes it: a furnished 10 x 7 m room, 0.1 m voxels, normals.
void BM_WallExtractionPerKeyframe(benchmark::State& state) {
  auto raw = test::BoxRoom(10, 7, 3, 60000, 0.03, 3, Eigen::Isometry3d(Eigen::Translation3d(-3, -3, -0.8)));
  auto desk = test::BoxRoom(1.6, 0.8, 0.75, 4000, 0.03, 4, Eigen::Isometry3d(Eigen::Translation3d(2, 1, -0.8)));
  raw.insert(raw.end(), desk.begin(), desk.end());
  BoundedVector<Eigen::Vector3f> down(70000), normals(70000);
  BoundedVector<Eigen::Matrix3f> covs(70000);
  VoxelDownsampler grid;
  grid.Init(70000);
  static_cast<void>(grid.Downsample(raw, 0.1f, down));
  KdTree tree;
  tree.Init(70000);
  static_cast<void>(tree.Build(down.span()));
  const Eigen::Vector3f origin(0, 0, 0);
  static_cast<void>(EstimateCovariances(down.span(), tree, {}, normals, covs, &origin));
  PlaneExtractor extractor;
  extractor.Init(70000);
  BoundedVector<ExtractedPlane> planes(64);
  for (auto _ : state) benchmark::DoNotOptimize(extractor.Extract(down.span(), normals.span(), {}, planes));
  state.counters["points"] = static_cast<double>(down.size());
  state.counters["planes"] = static_cast<double>(planes.size());
}
BENCHMARK(BM_WallExtractionPerKeyframe)->Unit(benchmark::kMillisecond);

// The same keyframe's preprocessing: voxel grid, k-d tree, normals and covariances (k = 10).
void BM_KeyframePreprocessing(benchmark::State& state) {
  const auto raw = test::BoxRoom(10, 7, 3, 60000, 0.03, 3, Eigen::Isometry3d(Eigen::Translation3d(-3, -3, -0.8)));
  BoundedVector<Eigen::Vector3f> down(70000), normals(70000);
  BoundedVector<Eigen::Matrix3f> covs(70000);
  VoxelDownsampler grid;
  grid.Init(70000);
  KdTree tree;
  tree.Init(70000);
  for (auto _ : state) {
    static_cast<void>(grid.Downsample(raw, 0.1f, down));
    static_cast<void>(tree.Build(down.span()));
    benchmark::DoNotOptimize(EstimateCovariances(down.span(), tree, {}, normals, covs));
  }
  state.counters["points_in"] = static_cast<double>(raw.size());
  state.counters["points_out"] = static_cast<double>(down.size());
}
BENCHMARK(BM_KeyframePreprocessing)->Unit(benchmark::kMillisecond);

struct Prepared {
  BoundedVector<Eigen::Vector3f> points{80000}, normals{80000};
  BoundedVector<Eigen::Matrix3f> covs{80000};
  KdTree tree;
  Prepared() { tree.Init(80000); }
  void From(const std::vector<Eigen::Vector3f>& raw, float leaf) {
    VoxelDownsampler grid;
    grid.Init(80000);
    static_cast<void>(grid.Downsample(raw, leaf, points));
    static_cast<void>(tree.Build(points.span()));
    static_cast<void>(EstimateCovariances(points.span(), tree, {}, normals, covs));
  }
};

// VGICP on the fast_gicp pair: alignment only (covariances and voxel map prepared), and the
// whole pipeline from raw clouds (downsampling, trees, covariances, voxel map, alignment).
void RunVgicp(benchmark::State& state, bool full) {
  const char* dir = std::getenv("MSGRAPHS_DATA_DIR");
  if (dir == nullptr) {
    state.SkipWithError("MSGRAPHS_DATA_DIR not set");
    return;
  }
  const auto target_raw = test::ReadCloud(std::string(dir) + "/registration/fast_gicp_251370668.pcd");
  const auto source_raw = test::ReadCloud(std::string(dir) + "/registration/fast_gicp_251371071.pcd");
  if (target_raw.empty() || source_raw.empty()) {
    state.SkipWithError("registration data absent");
    return;
  }
  const float leaf = static_cast<float>(state.range(0)) / 100.0f;
  Prepared target, source;
  target.From(target_raw, leaf);
  source.From(source_raw, leaf);
  GaussianVoxelMap map;
  map.Init(80000);
  static_cast<void>(map.Build(target.points.span(), target.covs.span(), 1.0));
  Vgicp vgicp;
  vgicp.Init(80000);
  double fitness = 0;
  for (auto _ : state) {
    if (full) {
      target.From(target_raw, leaf);
      source.From(source_raw, leaf);
      static_cast<void>(map.Build(target.points.span(), target.covs.span(), 1.0));
    }
    auto r = vgicp.Align(source.points.span(), source.covs.span(), map, target.points.span(), target.tree,
                         Eigen::Isometry3d::Identity(), {});
    fitness = r ? r->fitness : -1.0;
    benchmark::DoNotOptimize(r);
  }
  state.counters["target_points"] = static_cast<double>(target.points.size());
  state.counters["source_points"] = static_cast<double>(source.points.size());
  state.counters["fitness"] = fitness;
}
void BM_VgicpAlignFastGicpPair(benchmark::State& state) { RunVgicp(state, false); }
void BM_VgicpFullPipelineFastGicpPair(benchmark::State& state) { RunVgicp(state, true); }
BENCHMARK(BM_VgicpAlignFastGicpPair)->Arg(25)->Arg(10)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_VgicpFullPipelineFastGicpPair)->Arg(25)->Arg(10)->Unit(benchmark::kMillisecond);

}  // namespace
