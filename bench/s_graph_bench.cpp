// SPDX-License-Identifier: MIT
// The local S-Graph back end at 300 to 4,000 keyframes (a 1-hour mission at a keyframe a second): one keyframe's update (add the
// keyframe, its odometry and scan-matching factors, five plane observations, a room every ten
// keyframes, the bounded local solve) and a full solve, on a synthetic building walked
// out and back (a row of 10 m rooms). Per-update percentiles are counters (p50_ms, p99_ms);
// peak RSS is reported in MB.
//
//   build/host-release/bench/msgraphs_s_graph_bench
#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <random>
#include <vector>

#include "msgraphs/core/geometry/se3.hpp"
#include "msgraphs/core/graph/s_graph.hpp"
#include "msgraphs/core/graph/s_graph_solve_job.hpp"

namespace {

using namespace msgraphs::core;

// Building: rooms [10 i, 10 i + 10] x [-3, 3]; each room has its own four walls.
struct Building {
  SGraph graph;
  std::vector<std::array<std::int32_t, 4>>
      room_walls;  // per room: low x, high x, low y, high y (planes)
  std::vector<std::int32_t> room_ids;
  std::uint32_t floor_plane = 0;
  std::uint32_t last = 0;
  std::size_t keyframes = 0;
  std::mt19937 rng{7};

  static Eigen::Isometry3d TruePose(std::size_t k) {
    // Out along the building and back, one metre per keyframe, 500 m each way.
    const double s = static_cast<double>(k % 1000);
    const double x = s < 500 ? s : 1000 - s;
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = RotZ(s < 500 ? 0.0 : 3.14159265358979);
    T.translation() << x + 0.5, 0.8 * std::sin(0.3 * s), 0;
    return T;
  }

  PlaneMeasurement Measure(const Eigen::Vector3d& n, double d, const Eigen::Isometry3d& T) {
    std::normal_distribution<double> noise(0.0, 0.005);
    PlaneMeasurement z;
    z.normal = (T.linear().transpose() * n + Eigen::Vector3d(noise(rng), noise(rng), noise(rng)))
                   .normalized();
    z.d = d + n.dot(T.translation()) + noise(rng);
    z.basis_u = z.normal.unitOrthogonal();
    z.basis_v = z.normal.cross(z.basis_u);
    z.covariance = Eigen::Matrix3d::Identity() * 2.5e-5;
    return z;
  }

  explicit Building(std::size_t max_keyframes) {
    SGraphConfig config;
    config.max_keyframes = max_keyframes + 16;
    config.max_planes = 4096;
    config.max_rooms = 512;
    config.max_factors = max_keyframes * 12 + 4096;
    static_cast<void>(graph.Init(config));
    floor_plane = *graph.AddPlane(Eigen::Vector3d::UnitZ(), 0.5, PlaneClass::kFloor);
    for (int r = 0; r < 60; ++r) {
      const double x0 = 10.0 * r;
      std::array<std::int32_t, 4> w{};
      w[0] = static_cast<std::int32_t>(
          *graph.AddPlane(Eigen::Vector3d::UnitX(), -x0, PlaneClass::kWall));
      w[1] = static_cast<std::int32_t>(
          *graph.AddPlane(-Eigen::Vector3d::UnitX(), x0 + 10, PlaneClass::kWall));
      w[2] = static_cast<std::int32_t>(
          *graph.AddPlane(Eigen::Vector3d::UnitY(), 3, PlaneClass::kWall));
      w[3] = static_cast<std::int32_t>(
          *graph.AddPlane(-Eigen::Vector3d::UnitY(), 3, PlaneClass::kWall));
      room_walls.push_back(w);
      room_ids.push_back(-1);
    }
  }

  // One keyframe's worth of graph work, as the mapper does it.
  void AddKeyframe() {
    const std::size_t k = keyframes++;
    const Eigen::Isometry3d T = TruePose(k);
    const Eigen::Isometry3d guess =
        k == 0 ? T : graph.keyframe_pose(last) * (TruePose(k - 1).inverse() * T);
    const std::uint32_t id = *graph.AddKeyframe(static_cast<double>(k), guess);
    if (k > 0) {
      const Eigen::Isometry3d delta = TruePose(k - 1).inverse() * T;
      Matrix6d odometry = Matrix6d::Identity() * 1e3, scan = Matrix6d::Identity() * 2.5e3;
      static_cast<void>(
          graph.AddRelativePose(last, id, delta, odometry, RelativePoseKind::kOdometry));
      static_cast<void>(graph.AddRelativePose(last, id, delta, scan, RelativePoseKind::kScanMatch));
    }
    const std::size_t room =
        std::min<std::size_t>(59, static_cast<std::size_t>(T.translation().x() / 10.0));
    for (std::int32_t w : room_walls[room]) {
      const MapPlane p = graph.plane(static_cast<std::uint32_t>(w));
      static_cast<void>(
          graph.AddPlaneObservation(id, static_cast<std::uint32_t>(w), Measure(p.normal, p.d, T)));
    }
    static_cast<void>(
        graph.AddPlaneObservation(id, floor_plane, Measure(Eigen::Vector3d::UnitZ(), 0.5, T)));
    if (room_ids[room] < 0 && k % 10 == 9) {
      MapRoom r;
      r.centre = Eigen::Vector2d(10.0 * static_cast<double>(room) + 5, 0);
      r.walls = room_walls[room];
      room_ids[room] = static_cast<std::int32_t>(*graph.AddRoom(r));
      if (!graph.has_floor()) static_cast<void>(graph.SetFloor(r.centre));
      static_cast<void>(graph.AddFloorRoom(static_cast<std::uint32_t>(room_ids[room])));
    }
    static_cast<void>(graph.Solve(SolveKind::kLocal));
    last = id;
  }
};

double PeakRssMb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;
}

// Runs `step` once per iteration, timing each; reports p50/p99 and the peak RSS.
template <typename Step>
void TimeEachIteration(benchmark::State& state, Step step) {
  std::vector<double> ms;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    step();
    ms.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  std::sort(ms.begin(), ms.end());
  if (ms.empty()) return;
  state.counters["p50_ms"] = ms[ms.size() / 2];
  state.counters["p99_ms"] = ms[std::min(ms.size() - 1, ms.size() * 99 / 100)];
  state.counters["peak_rss_MB"] = PeakRssMb();
}

// One keyframe update on a graph that already holds `keyframes` keyframes.
void BM_SGraphKeyframeUpdate(benchmark::State& state) {
  const auto keyframes = static_cast<std::size_t>(state.range(0));
  Building b(keyframes + 4096);
  for (std::size_t i = 0; i < keyframes; ++i) b.AddKeyframe();
  static_cast<void>(b.graph.Solve(SolveKind::kFull));
  TimeEachIteration(state, [&] { b.AddKeyframe(); });
  state.counters["store_MB"] = static_cast<double>(b.graph.stats().store_bytes) / 1e6;
  state.counters["window_residuals"] =
      static_cast<double>(b.graph.stats().window_residuals_peak);
}
BENCHMARK(BM_SGraphKeyframeUpdate)
    ->Arg(300)
    ->Arg(500)
    ->Arg(2000)
    ->Arg(4000)
    ->Iterations(200)
    ->Unit(benchmark::kMillisecond);

// The same at capacity: every update also sparsifies one keyframe.
void BM_SGraphKeyframeUpdateAtCapacity(benchmark::State& state) {
  const auto keyframes = static_cast<std::size_t>(state.range(0));
  Building b(keyframes - 16);  // max_keyframes = keyframes
  for (std::size_t i = 0; i < keyframes; ++i) b.AddKeyframe();
  TimeEachIteration(state, [&] { b.AddKeyframe(); });
  state.counters["sparsified"] = static_cast<double>(b.graph.stats().sparsified);
}
BENCHMARK(BM_SGraphKeyframeUpdateAtCapacity)
    ->Arg(500)
    ->Arg(2000)
    ->Iterations(200)
    ->Unit(benchmark::kMillisecond);

// The fuller solve after a loop closure: everything but the origin moves.
void BM_SGraphFullSolve(benchmark::State& state) {
  const auto keyframes = static_cast<std::size_t>(state.range(0));
  Building b(keyframes);
  for (std::size_t i = 0; i < keyframes; ++i) b.AddKeyframe();
  TimeEachIteration(state, [&] { benchmark::DoNotOptimize(b.graph.Solve(SolveKind::kFull)); });
}
BENCHMARK(BM_SGraphFullSolve)
    ->Arg(300)
    ->Arg(500)
    ->Arg(2000)
    ->Arg(4000)
    ->Iterations(10)->Unit(benchmark::kMillisecond);

// The SLAM thread's share of a full solve in the background (SGraphSolveJob): copying the
// graph into the job (begin) and putting the solution back (apply); the solve itself (run) is
// another thread's, timed here for comparison with BM_SGraphFullSolve.
void BM_SGraphBackgroundSolve(benchmark::State& state) {
  const auto keyframes = static_cast<std::size_t>(state.range(0));
  Building b(keyframes);
  for (std::size_t i = 0; i < keyframes; ++i) b.AddKeyframe();
  SGraphSolveJob job;
  if (!job.Init(b.graph.config())) {
    state.SkipWithError("job init");
    return;
  }
  std::vector<double> begin_ms, run_ms, apply_ms;
  using Clock = std::chrono::steady_clock;
  const auto since = [](Clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  };
  for (auto _ : state) {
    auto t0 = Clock::now();
    if (!b.graph.BeginFullSolve(job)) {
      state.SkipWithError("begin");
      return;
    }
    begin_ms.push_back(since(t0));
    t0 = Clock::now();
    job.Complete();
    run_ms.push_back(since(t0));
    t0 = Clock::now();
    benchmark::DoNotOptimize(b.graph.ApplyFullSolve(job));
    apply_ms.push_back(since(t0));
  }
  const auto percentile = [](std::vector<double>& v, double q) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0.0 : v[std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size())))];
  };
  state.counters["begin_p50_ms"] = percentile(begin_ms, 0.5);
  state.counters["begin_p99_ms"] = percentile(begin_ms, 0.99);
  state.counters["apply_p50_ms"] = percentile(apply_ms, 0.5);
  state.counters["apply_p99_ms"] = percentile(apply_ms, 0.99);
  state.counters["run_p50_ms"] = percentile(run_ms, 0.5);
}
BENCHMARK(BM_SGraphBackgroundSolve)
    ->Arg(300)
    ->Arg(500)
    ->Arg(2000)
    ->Arg(4000)
    ->Iterations(10)->Unit(benchmark::kMillisecond);

// The walls' marginal covariances as the distiller asks for them at an exchange: every wall seen
// so far, from one factorisation of the whole graph (SGraph::PlaneMarginals: what the exchange
// computed on the SLAM thread before), and the SLAM thread's share now that a marginals job
// computes them elsewhere (begin: BeginPlaneMarginals' copy).
void BM_SGraphPlaneMarginals(benchmark::State& state) {
  const auto keyframes = static_cast<std::size_t>(state.range(0));
  Building b(keyframes);
  for (std::size_t i = 0; i < keyframes; ++i) b.AddKeyframe();
  std::vector<std::uint32_t> walls;
  for (std::uint32_t id = 0; id < b.graph.plane_slots(); ++id) {
    const MapPlane p = b.graph.plane(id);
    if (p.active && p.plane_class == PlaneClass::kWall && p.observations > 0) walls.push_back(id);
  }
  std::vector<Eigen::Matrix3d> covariances(walls.size());
  SGraphSolveJob job;
  if (!job.Init(b.graph.config())) {
    state.SkipWithError("job init");
    return;
  }
  using Clock = std::chrono::steady_clock;
  const auto since = [](Clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  };
  std::vector<double> marginals_ms, begin_ms;
  for (auto _ : state) {
    auto t0 = Clock::now();
    benchmark::DoNotOptimize(b.graph.PlaneMarginals(walls, covariances));
    marginals_ms.push_back(since(t0));
    t0 = Clock::now();
    static_cast<void>(b.graph.BeginPlaneMarginals(job, walls));
    begin_ms.push_back(since(t0));
    static_cast<void>(job.Release());  // not run: only the copy is timed
  }
  std::sort(marginals_ms.begin(), marginals_ms.end());
  std::sort(begin_ms.begin(), begin_ms.end());
  state.counters["walls"] = static_cast<double>(walls.size());
  if (!begin_ms.empty()) {
    state.counters["p50_ms"] = marginals_ms[marginals_ms.size() / 2];
    state.counters["max_ms"] = marginals_ms.back();
    state.counters["begin_p50_ms"] = begin_ms[begin_ms.size() / 2];
    state.counters["begin_max_ms"] = begin_ms.back();
  }
}
BENCHMARK(BM_SGraphPlaneMarginals)
    ->Arg(300)
    ->Arg(500)
    ->Arg(2000)
    ->Arg(4000)
    ->Iterations(5)->Unit(benchmark::kMillisecond);

}  // namespace
