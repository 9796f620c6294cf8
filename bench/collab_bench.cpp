// SPDX-License-Identifier: MIT
// The merge decision's search (alignment_search.hpp) between two maps of a grid of rooms: the
// collab thread runs it for every peer whenever a map or a free space changed. Arg 0: rooms
// per map (four walls each); arg 1: channels (one-direction alignments, the wall-pair families)
// on or off.
// And a place cloud built from a mapped hall (place_cloud.hpp): the fallback's answer to a
// peer, built in CollabPublisher::Prepare (the node's SLAM thread). Arg 0: keyframes, all
// within reach of the place (the worst case: a robot that walked the hall back and forth).
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "../tests/core/synthetic_clouds.hpp"
#include "msgraphs/core/collab/alignment_search.hpp"
#include "msgraphs/core/collab/place_cloud.hpp"
#include "msgraphs/core/collab/wall_index.hpp"
#include "msgraphs/core/slam/local_mapper.hpp"

namespace msgraphs::core {
namespace {

// Rooms 5 x 4 m in a grid, each wall's inner face, in a frame turned by yaw and moved by t.
std::vector<DistilledWall> GridOfRooms(int rooms, double yaw_rad, const Eigen::Vector2d& t_m) {
  const Eigen::Matrix2d R = PlanarTransform{yaw_rad, Eigen::Vector2d::Zero()}.R();
  std::vector<DistilledWall> walls;
  const int columns = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(rooms))));
  std::uint32_t id = 1;
  for (int k = 0; k < rooms; ++k) {
    const double x0 = 5.2 * (k % columns), y0 = 4.2 * (k / columns), x1 = x0 + 5.0, y1 = y0 + 4.0;
    const Eigen::Vector2d corners[4] = {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
    for (int side = 0; side < 4; ++side) {
      const Eigen::Vector2d a = R * corners[side] + t_m, b = R * corners[(side + 1) % 4] + t_m;
      const Eigen::Vector2d u = (b - a).normalized();
      DistilledWall w;
      w.id = id++;
      w.normal = Eigen::Vector3d(-u.y(), u.x(), 0.0);  // the inside: corners run anticlockwise
      w.d = -w.normal.head<2>().dot(a);
      w.a = a;
      w.b = b;
      walls.push_back(w);
    }
  }
  return walls;
}

void BM_AlignmentSearch(benchmark::State& state) {
  const int rooms = static_cast<int>(state.range(0));
  const std::vector<DistilledWall> wa = GridOfRooms(rooms, 0.0, Eigen::Vector2d::Zero());
  const std::vector<DistilledWall> wb = GridOfRooms(rooms, 0.7, Eigen::Vector2d(3.0, -8.0));
  WallIndex a, b;
  if (!a.Init(wa.size()) || !b.Init(wb.size())) state.SkipWithError("WallIndex::Init");
  a.Build(wa, 0.5);
  b.Build(wb, 0.5);
  AlignmentSearchConfig config;
  if (state.range(1) == 0) config.min_channel_agreement_m = 0;
  AlignmentSearch search;
  if (!search.Init(config)) state.SkipWithError("AlignmentSearch::Init");
  for (auto _ : state) {
    benchmark::DoNotOptimize(search.Search(a, {}, b, {}, {}, false));
  }
  state.counters["walls"] = static_cast<double>(wa.size());
  state.counters["hypotheses"] = static_cast<double>(search.hypotheses().size());
  state.counters["channels"] = static_cast<double>(search.channels().size());
  state.counters["families"] = static_cast<double>(search.stats().channel_families);
  state.counters["truncated"] = search.truncated() ? 1 : 0;
}
// 250 rooms (1,000 walls, the distiller's capacity) take 18 s a search and truncate: see docs/performance.md.
BENCHMARK(BM_AlignmentSearch)->Args({25, 0})->Args({25, 1})->Args({100, 0})->Args({100, 1})->Unit(benchmark::kMillisecond);

// A 24 x 16 m hall (3 m high) mapped with perfect odometry, a keyframe a metre, back and forth
// along its middle third.
bool MapTheHall(int keyframes, LocalMapper& mapper) {
  constexpr double kSx = 24.0, kSy = 16.0, kSz = 3.0;
  LocalMapperConfig config;
  config.max_scan_points = 25000;
  config.graph.max_keyframes = static_cast<std::size_t>(keyframes) + 8;
  config.graph.max_factors = config.graph.max_keyframes * 64;
  config.cloud_store_points = config.graph.max_keyframes * 12000;
  if (!mapper.Init(config)) return false;
  Eigen::Isometry3d T_world_first = test::PlanarPose(8.0, 8.0, 0.0);
  T_world_first.translation().z() = config.base_height_m;
  const std::vector<float> times(20000, 0.1f);
  for (int i = 0; i < keyframes; ++i) {
    const int leg = (i / 8) % 2, step = i % 8;
    Eigen::Isometry3d T_world_base = T_world_first;
    T_world_base.translation().x() += leg == 0 ? step : 8 - step;
    T_world_base.translation().y() += 0.25 * ((i / 16) % 4);
    const Eigen::Isometry3d odometry = T_world_first.inverse() * T_world_base;
    const double t = 10.0 + i;
    if (!mapper.AddOdometry(t - 0.15, odometry) || !mapper.AddOdometry(t + 0.05, odometry)) return false;
    const auto points = test::BoxRoom(kSx, kSy, kSz, 20000, 0.01, static_cast<std::uint32_t>(i + 1),
                                      (T_world_base * config.T_base_lidar).inverse());
    if (!mapper.AddScan({points, times, t - 0.1, t})) return false;
  }
  return static_cast<bool>(mapper.Finish());
}

void BM_PlaceCloudBuild(benchmark::State& state) {
  const int keyframes = static_cast<int>(state.range(0));
  LocalMapper mapper;
  if (!MapTheHall(keyframes, mapper)) {
    state.SkipWithError("mapping the hall failed");
    return;
  }
  PlaceCloudBuilder builder;
  if (!builder.Init({})) state.SkipWithError("PlaceCloudBuilder::Init");
  BoundedVector<Eigen::Vector3f> cloud(builder.config().max_points);
  const Eigen::Vector2d centre_map(4.0, -5.0);  // 3 m from the hall's long wall: the disc holds a stretch of it
  for (auto _ : state) {
    benchmark::DoNotOptimize(builder.Build(mapper, centre_map, 5.0f, cloud));
  }
  state.counters["keyframes"] = static_cast<double>(mapper.stats().keyframes);
  state.counters["points"] = static_cast<double>(cloud.size());
  state.counters["voxel_m"] = static_cast<double>(builder.last_voxel_m());
}
BENCHMARK(BM_PlaceCloudBuild)->Arg(50)->Arg(200)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace msgraphs::core
