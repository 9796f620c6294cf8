// SPDX-License-Identifier: MIT
// msgraphs_slam: one robot's recording (VLP-16 pcap + CAN candump) through the drivers and the
// local S-Graph, as fast as possible in lock-step (odometry is fed up to each scan's end first).
// Writes the keyframes (TUM, base frame), the encoder odometry at the same stamps (TUM), walls
// and rooms (CSV), and prints per-stage timing percentiles, peak memory and, when the run
// directory holds ground truth, the ATE of both against it (truth interpolated at each
// keyframe's stamp; how many keyframes it paired and why not the others) and the walls and
// rooms found against the world's truth.
//
// --matches FILE writes every keyframe's scan match (CSV: the two stamps, the result, the fitness,
// the fitness gate's limit, the transform) for tools/eval/match_errors.py to judge against the
// truth; --fitness-floor and --fitness-outlier-z set the gate as the node's [mapping] keys do.
// --odometry-from-truth feeds the ground truth (at 50 Hz, interpolated) as the encoders: what is
// left of the ATE is the front end's and the graph's own (docs/s-graph.md, "Plane covariance").
// --speed X paces the scans at X times the recorded rate instead of as fast as possible (each
// scan waits for its recorded time from the first, divided by X): the background full solve
// then has the time it has onboard at X = 1, or 1/X of it (the schedule counts keyframes
// either way).
//
//   msgraphs_slam --run DIR --robot N [--out DIR] [--markdown] [--verbose] [--max-keyframes N]
//                 [--sparsify-plane-share S]
//                 [--matches FILE] [--fitness-floor M2] [--fitness-outlier-z Z]
//                 [--odometry-from-truth] [--speed X]
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <string>
#include <thread>
#include <vector>

#include "msgraphs/core/slam/local_mapper.hpp"
#include "msgraphs/drivers/velodyne/recorded_scans.hpp"
#include "msgraphs/tools/ate.hpp"
#include "msgraphs/tools/candump_odometry.hpp"
#include "msgraphs/tools/keyframe_timing.hpp"
#include "msgraphs/tools/solver_thread.hpp"
#include "msgraphs/tools/truth_pairing.hpp"
#include "msgraphs/tools/tum.hpp"
#include "truth.hpp"
#include "world.hpp"

namespace {

using namespace msgraphs;
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// "0.021" or "n/a": a failed ATE is never printed as a number.
std::string AteCell(const tools::AteResult& ate) {
  char b[32];
  std::snprintf(b, sizeof b, "%.3f", ate.rmse);
  return ate.ok ? b : "n/a";
}

// The ATE lines: the figures, and how many keyframes the truth could score and why not the rest.
void PrintAte(std::size_t keyframes,
              const tools::TruthTrajectory& truth,
              const tools::AteResult& slam,
              const tools::AteResult& odometry) {
  if (slam.ok && odometry.ok) {
    std::printf(
        "ATE RMSE (SE(3) Umeyama, %zu keyframes): S-Graph %.3f m (max %.3f), encoder odometry "
        "%.3f m (max %.3f)\n",
        slam.poses(), slam.rmse, slam.max, odometry.rmse, odometry.max);
  } else {
    std::printf("ATE not computed: %s\n", slam.ok ? odometry.error : slam.error);
  }
  std::printf(
      "truth paired at %zu of %zu keyframes (unpaired: %s); %zu truth samples, median period "
      "%.4f s, gap limit %.4f s\n",
      slam.pairs.paired, keyframes, slam.pairs.DescribeUnpaired().c_str(), truth.samples().size(),
      truth.median_period_s(), truth.gap_limit_s());
}

}  // namespace

int main(int argc, char** argv) {
  std::string run, out_dir;
  int robot = 1;
  bool markdown = false, verbose = false, odometry_from_truth = false;
  std::size_t max_keyframes = 0;
  double plane_share = -1;
  long full_solve_lag = -1;
  std::string matches_path;
  double fitness_floor_m2 = -1, fitness_outlier_z = -1;
  double speed = 0;  // 0: as fast as possible
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--run" && i + 1 < argc)
      run = argv[++i];
    else if (a == "--robot" && i + 1 < argc)
      robot = std::atoi(argv[++i]);
    else if (a == "--out" && i + 1 < argc)
      out_dir = argv[++i];
    else if (a == "--max-keyframes" && i + 1 < argc)
      max_keyframes = static_cast<std::size_t>(std::atol(argv[++i]));
    else if (a == "--sparsify-plane-share" && i + 1 < argc) {
      // Strict: a typo must not turn carrying off (atof's 0); the range is the config's.
      char* end = nullptr;
      plane_share = std::strtod(argv[++i], &end);
      if (end == argv[i] || *end != '\0' || !(plane_share >= 0 && plane_share < 1)) {
        std::fprintf(stderr, "--sparsify-plane-share: a number at least 0 and below 1, not '%s'\n", argv[i]);
        return 2;
      }
    }
    else if (a == "--full-solve-lag" && i + 1 < argc)
      full_solve_lag = std::atol(argv[++i]);
    else if (a == "--matches" && i + 1 < argc)
      matches_path = argv[++i];
    else if (a == "--fitness-floor" && i + 1 < argc)
      fitness_floor_m2 = std::atof(argv[++i]);
    else if (a == "--fitness-outlier-z" && i + 1 < argc)
      fitness_outlier_z = std::atof(argv[++i]);
    else if (a == "--speed" && i + 1 < argc)
      speed = std::atof(argv[++i]);
    else if (a == "--odometry-from-truth")
      odometry_from_truth = true;
    else if (a == "--markdown")
      markdown = true;
    else if (a == "--verbose")
      verbose = true;
    else {
      std::fprintf(stderr,
                   "usage: msgraphs_slam --run DIR --robot N [--out DIR] [--markdown] [--verbose] "
                   "[--max-keyframes N] [--sparsify-plane-share S] [--full-solve-lag N] [--matches FILE] [--fitness-floor M2] "
                   "[--fitness-outlier-z Z] [--odometry-from-truth] [--speed X]\n");
      return 2;
    }
  }
  if (!(speed >= 0) || !std::isfinite(speed)) {
    std::fprintf(stderr, "slam: --speed must be a positive factor (0: as fast as possible)\n");
    return 2;
  }
  const fs::path dir = fs::path(run) / ("robot" + std::to_string(robot));
  if (run.empty() || !fs::exists(dir / "velodyne.pcap") || !fs::exists(dir / "odometry.log")) {
    std::fprintf(stderr, "slam: %s needs velodyne.pcap and odometry.log\n", dir.c_str());
    return 2;
  }
  core::LocalMapperConfig config;
  if (max_keyframes > 0) config.graph.max_keyframes = max_keyframes;
  if (plane_share >= 0) config.graph.sparsify_plane_share = plane_share;
  if (full_solve_lag >= 0) config.full_solve_lag_keyframes = static_cast<std::size_t>(full_solve_lag);
  if (fitness_floor_m2 >= 0) config.scan_match_max_fitness_m2 = fitness_floor_m2;
  if (fitness_outlier_z >= 0) config.scan_match_fitness_outlier_z = fitness_outlier_z;
  std::vector<tools::StampedPose> truth_as_odometry;
  if (odometry_from_truth) {
    const tools::TruthTrajectory truth(tools::ReadTum((dir / "ground_truth.tum").string()));
    if (truth.samples().size() < 2) {
      std::fprintf(stderr, "slam: --odometry-from-truth needs %s\n", (dir / "ground_truth.tum").c_str());
      return 2;
    }
    const Eigen::Isometry3d T_start_world = truth.samples().front().T.inverse();
    for (double t = truth.samples().front().t; t <= truth.samples().back().t; t += 0.02) {
      if (const auto at = truth.At(t); at.ok) truth_as_odometry.push_back({t, T_start_world * at.T});
    }
    config.odometry_capacity = std::max(config.odometry_capacity, truth_as_odometry.size() + 16);
  }
  std::FILE* matches = nullptr;
  if (!matches_path.empty()) {
    matches = std::fopen(matches_path.c_str(), "w");
    if (matches == nullptr) {
      std::fprintf(stderr, "slam: cannot write %s\n", matches_path.c_str());
      return 1;
    }
    std::fprintf(matches, "from_s,to_s,result,motion_seeded,fitness_m2,limit_m2,x,y,z,qx,qy,qz,qw\n");
  }
  std::string world_error;
  std::optional<sim::World> world;
  if (fs::exists(fs::path(run) / "world.world"))
    world = sim::LoadWorld((fs::path(run) / "world.world").string(), world_error);
  core::LocalMapper mapper;
  tools::SolverThread solver;  // the background full solve's runner (joined before the mapper goes)
  if (auto s = mapper.Init(config); !s) {
    std::fprintf(stderr, "slam: %s\n", s.error().detail);
    return 1;
  }
  rusage after_init{};
  getrusage(RUSAGE_SELF, &after_init);
  auto scans = drivers::velodyne::RecordedScans::Open((dir / "velodyne.pcap").string());
  auto candump = tools::CandumpOdometry::Open((dir / "odometry.log").c_str());
  if (!scans || !candump) {
    std::fprintf(stderr, "slam: cannot open the recording in %s\n", dir.c_str());
    return 1;
  }
  const auto to_mapper = [&](double stamp_s, const Eigen::Isometry3d& T_odom_base) {
    static_cast<void>(mapper.AddOdometry(stamp_s, T_odom_base));
  };
  if (odometry_from_truth) {
    candump->Stop();  // the encoders are not read
    for (const tools::StampedPose& p : truth_as_odometry) static_cast<void>(mapper.AddOdometry(p.t, p.T));
  }
  std::vector<Eigen::Vector3f> points;
  std::vector<float> times;
  tools::KeyframeTiming timer;
  const auto t_start = Clock::now();
  std::size_t scan_count = 0;
  double first_end_s = 0;
  while (const drivers::velodyne::Scan* next = scans->Next()) {
    const auto& scan = *next;
    ++scan_count;
    points.clear();
    times.clear();
    for (const auto& p : scan.points) {
      points.emplace_back(p.x_m, p.y_m, p.z_m);
      times.push_back(static_cast<float>(p.time_offset_ns * 1e-9));
    }
    core::LidarScanView view{points, times, scan.start_time.seconds_since_epoch(),
                             scan.end_time.seconds_since_epoch()};
    if (speed > 0) {
      // Paced: the scan is handed over when its sweep has ended, at the recorded rate x speed.
      if (scan_count == 1) first_end_s = view.end_s;
      std::this_thread::sleep_until(
          t_start + std::chrono::duration_cast<Clock::duration>(
                        std::chrono::duration<double>((view.end_s - first_end_s) / speed)));
    }
    candump->Until(view.end_s + 0.05, to_mapper);
    const auto loops_before = mapper.loop_closer().stats().accepted;
    const auto rejected_before = mapper.loop_closer().stats().rejected_after_solve;
    const auto sweep_start = Clock::now();
    const auto outcome = mapper.AddScan(view, &timer);
    if (outcome && *outcome == core::ScanOutcome::kNotKeyframe)
      timer.Sweep(std::chrono::duration<double, std::milli>(Clock::now() - sweep_start).count());
    solver.Follow(mapper);  // a full solve begun at this keyframe: on its own thread
    const core::ScanMatchRecord& m = mapper.last_scan_match();
    if (matches != nullptr && outcome && *outcome == core::ScanOutcome::kKeyframe && m.attempted) {
      const Eigen::Quaterniond q(m.T_from_to.linear());
      const Eigen::Vector3d t = m.T_from_to.translation();
      std::fprintf(matches, "%.6f,%.6f,%s,%d,%.6f,%.6f,%.6f,%.6f,%.6f,%.8f,%.8f,%.8f,%.8f\n",
                   m.from_s, m.to_s, m.result, m.motion_seeded ? 1 : 0, m.fitness_m2, m.limit_m2,
                   t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w());
    }
    const auto& l = mapper.loop_closer().stats();
    if (verbose && l.accepted + l.rejected_after_solve != loops_before + rejected_before) {
      std::printf(
          "loop closure: keyframe %u to %u, fitness %.4f m^2, moved the estimate %.3f m%s\n",
          l.last_to, l.last_from, l.last_fitness_m2, l.last_correction_m,
          l.rejected_after_solve != rejected_before ? ": contradicted after the solve, removed"
                                                    : "");
    }
  }
  solver.Join();
  static_cast<void>(mapper.Finish());
  if (matches != nullptr && std::fclose(matches) != 0) {
    std::fprintf(stderr, "slam: writing %s failed\n", matches_path.c_str());
    return 1;
  }
  const double seconds = std::chrono::duration<double>(Clock::now() - t_start).count();

  // Outputs.
  const core::SGraph& graph = mapper.graph();
  std::vector<tools::StampedPose> slam, encoders;
  for (std::uint32_t k = graph.FirstKeyframe(); k != core::SGraph::kNoKeyframe;
       k = graph.NextKeyframe(k)) {
    slam.push_back({graph.keyframe_stamp(k), graph.keyframe_pose(k)});
    encoders.push_back({graph.keyframe_stamp(k), mapper.keyframe_odometry(k)});
  }
  if (!out_dir.empty()) {
    fs::create_directories(out_dir);
    static_cast<void>(tools::WriteTum((fs::path(out_dir) / "keyframes.tum").string(), slam));
    static_cast<void>(
        tools::WriteTum((fs::path(out_dir) / "odometry_keyframes.tum").string(), encoders));
    std::ofstream walls(fs::path(out_dir) / "walls.csv");
    walls << "id,class,nx,ny,nz,d,observations,x1,y1,x2,y2\n";
    for (std::uint32_t i = 0; i < graph.plane_slots(); ++i) {
      const core::MapPlane p = graph.plane(i);
      const auto& e = mapper.plane_mapper().extent(i);
      walls << i << ',' << static_cast<int>(p.plane_class) << ',' << p.normal.x() << ','
            << p.normal.y() << ',' << p.normal.z() << ',' << p.d << ',' << p.observations << ','
            << e.a.x() << ',' << e.a.y() << ',' << e.b.x() << ',' << e.b.y() << '\n';
    }
    std::ofstream rooms(fs::path(out_dir) / "rooms.csv");
    rooms << "id,shape,x,y,wall0,wall1,wall2,wall3\n";
    for (std::uint32_t i = 0; i < graph.room_slots(); ++i) {
      const core::MapRoom r = graph.room(i);
      if (!r.active) continue;
      rooms << i << ',' << (r.shape == core::RoomShape::kFourWall ? "room" : "corridor") << ','
            << r.centre.x() << ',' << r.centre.y() << ',' << r.walls[0] << ',' << r.walls[1] << ','
            << r.walls[2] << ',' << r.walls[3] << '\n';
    }
  }
  const tools::TruthTrajectory truth_trajectory(
      tools::ReadTum((dir / "ground_truth.tum").string()));
  const std::vector<tools::StampedPose>& truth = truth_trajectory.samples();
  const tools::AteResult ate_slam = tools::ComputeAte(slam, truth_trajectory),
                         ate_odometry = tools::ComputeAte(encoders, truth_trajectory);
  if (!out_dir.empty() && ate_slam.ok) {
    // Per-keyframe error after the alignment, to see where an estimate went wrong; keyframes
    // without truth are listed in the header with their reasons.
    const tools::PairedPoses paired = tools::PairWithTruth(slam, truth_trajectory);
    std::ofstream errors(fs::path(out_dir) / "keyframe_errors.txt");
    errors << "# stamp error_m; " << paired.counts.paired << " of " << slam.size()
           << " keyframes paired with the truth (unpaired: " << paired.counts.DescribeUnpaired()
           << ")\n";
    for (std::size_t i = 0; i < paired.estimate.size(); ++i) {
      errors << std::fixed << paired.estimate[i].t << ' '
             << (ate_slam.T_truth_estimate * paired.estimate[i].T.translation() -
                 paired.truth[i].T.translation())
                    .norm()
             << '\n';
    }
  }

  // Walls and rooms against the world (through the ATE alignment).
  std::size_t walls_mapped = 0, walls_true = 0, rooms_mapped = 0, rooms_correct = 0,
              rooms_visited = 0;
  double wall_offset_sum = 0;
  if (world && ate_slam.ok) {
    const Eigen::Isometry3d& A = ate_slam.T_truth_estimate;
    std::map<std::string, bool> room_matched, visited;
    for (const tools::StampedPose& s : truth) {
      if (const sim::Room* r = world->RoomAt(s.T.translation().head<2>(), 0)) visited[r->id] = true;
    }
    rooms_visited = visited.size();
    for (std::uint32_t i = 0; i < graph.plane_slots(); ++i) {
      const core::MapPlane p = graph.plane(i);
      if (!p.active || p.plane_class != core::PlaneClass::kWall || p.observations < 2) continue;
      ++walls_mapped;
      const Eigen::Vector3d n = A.linear() * p.normal;
      const auto& e = mapper.plane_mapper().extent(i);
      const Eigen::Vector2d mid =
          (A * Eigen::Vector3d(0.5 * (e.a.x() + e.b.x()), 0.5 * (e.a.y() + e.b.y()), 0)).head<2>();
      double best = 1e9;
      for (const sim::Wall& w : world->walls) {
        // Both faces of the true wall: n pointing away from the wall, offset by half the thickness.
        for (double side : {1.0, -1.0}) {
          const Eigen::Vector2d fn = w.normal() * side;
          const double fd = -fn.dot(w.start) - 0.5 * w.thickness_m;
          if (fn.dot(n.head<2>().normalized()) < std::cos(5.0 * std::numbers::pi / 180.0)) continue;
          const double along = (mid - w.start).dot(w.direction());
          if (along < -0.5 || along > w.length() + 0.5) continue;
          best = std::min(best, std::fabs(fn.dot(mid) + fd));
        }
      }
      if (best < 0.10) {
        ++walls_true;
        wall_offset_sum += best;
      }
    }
    for (std::uint32_t i = 0; i < graph.room_slots(); ++i) {
      const core::MapRoom r = graph.room(i);
      if (!r.active) continue;
      ++rooms_mapped;
      const Eigen::Vector2d c = (A * Eigen::Vector3d(r.centre.x(), r.centre.y(), 0)).head<2>();
      const sim::Room* truth_room = world->RoomAt(c, 0);
      if (truth_room != nullptr && !room_matched[truth_room->id]) {
        room_matched[truth_room->id] = true;
        ++rooms_correct;
      }
    }
  }
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  const auto gs = graph.stats();
  const auto& ms = mapper.stats();
  if (markdown) {
    std::printf(
        "| %s | %d | %zu | %s | %s | %zu / %zu | %zu / %zu (%zu visited) | %llu | %.0f | %.1f "
        "|\n",
        world ? world->name.c_str() : run.c_str(), robot, slam.size(),
        AteCell(ate_odometry).c_str(), AteCell(ate_slam).c_str(), walls_true, walls_mapped,
        rooms_correct, rooms_mapped, rooms_visited,
        static_cast<unsigned long long>(ms.loop_closures), tools::KeyframeTiming::Percentile(timer.total(), 0.5),
        static_cast<double>(usage.ru_maxrss) / 1024.0);
    return 0;
  }
  std::printf("robot %d: %zu scans, %zu keyframes, %.1f s (%.1f x real time)\n", robot, scan_count,
              slam.size(), seconds,
              static_cast<double>(scan_count) * 0.1 / std::max(1e-9, seconds));
  PrintAte(slam.size(), truth_trajectory, ate_slam, ate_odometry);
  std::printf(
      "graph: %zu keyframes (peak %zu, %zu sparsified), %zu planes, %zu rooms, %zu floor; %zu "
      "factors "
      "(odometry %zu, scan matching %zu, loop %zu, sparsified %zu, plane %zu, room %zu, wall-wall "
      "%zu, floor %zu)\n",
      gs.keyframes, gs.keyframes_peak, gs.sparsified, gs.planes, gs.rooms, gs.floors, gs.factors,
      gs.relative_factors[0], gs.relative_factors[1], gs.relative_factors[2],
      gs.relative_factors[3], gs.plane_factors, gs.room_factors, gs.wall_wall_factors,
      gs.floor_factors);
  std::printf(
      "sparsification: %zu of them carrying loops, %zu loops carried to a neighbour (%zu fused "
      "with one there), %zu constraints dropped; plane observations %zu carried (%zu fused), %zu "
      "dropped; keyframes refused %llu (mapper %llu), odometry or scan-matching factors refused "
      "%llu\n",
      gs.sparsified_with_loops, gs.sparsify_carried, gs.sparsify_merged, gs.sparsify_dropped,
      gs.sparsify_planes_carried, gs.sparsify_planes_fused, gs.sparsify_planes_dropped,
      static_cast<unsigned long long>(gs.rejected_keyframes),
      static_cast<unsigned long long>(ms.keyframes_refused),
      static_cast<unsigned long long>(ms.chain_factors_refused));
  std::printf(
      "refused: pose %llu, stamp %llu, information %llu, behind %llu, missing node %llu, capacity "
      "%llu; solves %llu "
      "(%llu at their limit, %llu undone)\n",
      static_cast<unsigned long long>(gs.rejected_pose),
      static_cast<unsigned long long>(gs.rejected_stamp),
      static_cast<unsigned long long>(gs.rejected_information),
      static_cast<unsigned long long>(gs.rejected_behind),
      static_cast<unsigned long long>(gs.rejected_missing_node),
      static_cast<unsigned long long>(gs.rejected_capacity),
      static_cast<unsigned long long>(gs.solves),
      static_cast<unsigned long long>(gs.solves_not_converged),
      static_cast<unsigned long long>(gs.solves_undone));
  std::printf(
      "full solves: %llu (lag %zu keyframes: %llu applied in the background, %llu waited for at "
      "their keyframe, %llu unusable); loop closures %llu (%llu unchecked)\n",
      static_cast<unsigned long long>(ms.full_solves), config.full_solve_lag_keyframes,
      static_cast<unsigned long long>(ms.full_solves_background),
      static_cast<unsigned long long>(ms.full_solves_waited),
      static_cast<unsigned long long>(gs.background_unusable),
      static_cast<unsigned long long>(ms.loop_closures),
      static_cast<unsigned long long>(ms.loops_unchecked));
  std::printf(
      "scan matching: %llu accepted; rejected fitness %llu, overlap %llu, diverged %llu, failed "
      "%llu; %llu accepted above the fitness floor (limit now %.4f m^2); odometry gaps at %llu "
      "keyframes, slips gated at %llu\n",
      static_cast<unsigned long long>(ms.scan_match_accepted),
      static_cast<unsigned long long>(ms.scan_match_rejected_fitness),
      static_cast<unsigned long long>(ms.scan_match_rejected_overlap),
      static_cast<unsigned long long>(ms.scan_match_rejected_diverged),
      static_cast<unsigned long long>(ms.scan_match_rejected_failed),
      static_cast<unsigned long long>(ms.scan_match_above_floor), ms.scan_match_fitness_limit_m2,
      static_cast<unsigned long long>(ms.odometry_gap_keyframes),
      static_cast<unsigned long long>(ms.odometry_slips));
  const auto& ls = mapper.loop_closer().stats();
  std::printf(
      "loop closure: %llu queries, %llu candidates, %llu verified, %llu accepted (fitness %llu, "
      "overlap %llu, not converged %llu, contradicted after the solve %llu rejected)\n",
      static_cast<unsigned long long>(ls.queries), static_cast<unsigned long long>(ls.candidates),
      static_cast<unsigned long long>(ls.verified), static_cast<unsigned long long>(ls.accepted),
      static_cast<unsigned long long>(ls.rejected_fitness),
      static_cast<unsigned long long>(ls.rejected_overlap),
      static_cast<unsigned long long>(ls.rejected_not_converged),
      static_cast<unsigned long long>(ls.rejected_after_solve));
  const auto& ps = mapper.plane_mapper().stats();
  const auto& rs = mapper.room_mapper().stats();
  std::printf(
      "planes: %llu associated, %llu created, %llu furniture faces skipped, %llu refused; rooms: "
      "%llu updates, %llu detections, %llu created, %llu matched, %llu corridors completed, %llu "
      "wall-wall; floor found only by the floor search at %llu keyframes\n",
      static_cast<unsigned long long>(ps.associated), static_cast<unsigned long long>(ps.created),
      static_cast<unsigned long long>(ps.furniture), static_cast<unsigned long long>(ps.rejected),
      static_cast<unsigned long long>(rs.updates), static_cast<unsigned long long>(rs.detections),
      static_cast<unsigned long long>(rs.created), static_cast<unsigned long long>(rs.matched),
      static_cast<unsigned long long>(rs.upgraded), static_cast<unsigned long long>(rs.wall_wall),
      static_cast<unsigned long long>(mapper.stats().floors_found));
  if (world) {
    std::printf(
        "against the world: %zu of %zu mapped walls are true faces (mean offset %.3f m); %zu of "
        "%zu rooms are distinct true rooms (%zu rooms visited)\n",
        walls_true, walls_mapped,
        wall_offset_sum / std::max<double>(1, static_cast<double>(walls_true)), rooms_correct,
        rooms_mapped, rooms_visited);
  }
  std::printf(
      "memory: graph stores %.1f MB, cloud store peak %zu of %zu points, local map peak %zu "
      "points, RSS after Init %.1f MB, peak RSS %.1f MB\n",
      static_cast<double>(gs.store_bytes) / 1e6, mapper.clouds().peak_points(),
      mapper.clouds().capacity_points(), ms.local_map_points_peak,
      static_cast<double>(after_init.ru_maxrss) / 1024.0,
      static_cast<double>(usage.ru_maxrss) / 1024.0);
  timer.Print(stdout);
  return 0;
}
