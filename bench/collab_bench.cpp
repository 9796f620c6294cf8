// SPDX-License-Identifier: MIT
// The merge decision's search (alignment_search.hpp) between two maps of a grid of rooms: the
// collab thread runs it for every peer whenever a map or a free space changed. Arg 0: rooms
// per map (four walls each); arg 1: channels (one-direction alignments, the wall-pair families)
// on or off.
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "msgraphs/core/collab/alignment_search.hpp"
#include "msgraphs/core/collab/wall_index.hpp"

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

}  // namespace
}  // namespace msgraphs::core
