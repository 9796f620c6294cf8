// SPDX-License-Identifier: MIT
// msgraphs_eval_perception: runs the perception front end (decode, deskew, downsample, normals,
// walls, free space, rooms) over a simulated run with ground-truth poses, and compares the rooms
// found with the world's true rooms. Poses come from ground truth on purpose: this measures
// perception alone; the SLAM back end is evaluated separately.
//
//   msgraphs_eval_perception --run runs/office [--keyframe-spacing-m 1.0] [--markdown]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <sstream>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "msgraphs/core/descriptors/scan_context.hpp"
#include "msgraphs/core/perception/covariances.hpp"
#include "msgraphs/core/perception/deskew.hpp"
#include "msgraphs/core/perception/free_space_grid.hpp"
#include "msgraphs/core/perception/kdtree.hpp"
#include "msgraphs/core/perception/plane_extraction.hpp"
#include "msgraphs/core/perception/room_segmentation.hpp"
#include "msgraphs/core/perception/voxel_grid.hpp"
#include "msgraphs/drivers/pcap/pcap_reader.hpp"
#include "msgraphs/drivers/velodyne/data_packet_decoder.hpp"
#include "msgraphs/drivers/velodyne/device_clock.hpp"
#include "msgraphs/drivers/velodyne/recorded_scans.hpp"
#include "msgraphs/drivers/velodyne/scan_assembler.hpp"
#include "msgraphs/tools/truth_pairing.hpp"
#include "msgraphs/tools/tum.hpp"
#include "truth.hpp"
#include "world.hpp"

namespace {

using namespace msgraphs;
namespace fs = std::filesystem;

// Walls merged across keyframes: the same line (angle, offset) with touching extents.
struct MergedWall {
  core::MapWall wall;
  double weight = 0;
};

void MergeWall(std::vector<MergedWall>& walls, const core::MapWall& w, double weight) {
  for (MergedWall& m : walls) {
    if (m.wall.normal.dot(w.normal) < std::cos(5.0 * std::numbers::pi / 180.0)) continue;
    const Eigen::Vector2d mid = 0.5 * (w.a + w.b);
    if (std::fabs(m.wall.normal.dot(mid) + m.wall.d) > 0.15) continue;
    const Eigen::Vector2d mdir(-m.wall.normal.y(), m.wall.normal.x());
    double a0 = mdir.dot(m.wall.a), a1 = mdir.dot(m.wall.b), b0 = mdir.dot(w.a), b1 = mdir.dot(w.b);
    if (a0 > a1) std::swap(a0, a1);
    if (b0 > b1) std::swap(b0, b1);
    if (b0 > a1 + 0.5 || a0 > b1 + 0.5) continue;  // separate pieces of a line
    // Weighted average of the line, union of the extents.
    const double total = m.weight + weight;
    Eigen::Vector2d n = (m.wall.normal * m.weight + w.normal * weight).normalized();
    const double d = (m.wall.d * m.weight + w.d * weight) / total;
    const Eigen::Vector2d ndir(-n.y(), n.x());
    const double lo = std::min(a0, b0), hi = std::max(a1, b1);
    // Extents were measured along the old direction; re-place them on the new line.
    const Eigen::Vector2d foot = -d * n;
    m.wall.normal = n;
    m.wall.d = d;
    m.wall.a = foot + ndir * lo;
    m.wall.b = foot + ndir * hi;
    m.weight = total;
    return;
  }
  walls.push_back({w, weight});
  walls.back().wall.id = static_cast<std::uint32_t>(walls.size() - 1);
}

}  // namespace

int main(int argc, char** argv) {
  std::string run;
  double spacing = 1.0;
  bool markdown = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--run" && i + 1 < argc)
      run = argv[++i];
    else if (a == "--keyframe-spacing-m" && i + 1 < argc)
      spacing = std::atof(argv[++i]);
    else if (a == "--markdown")
      markdown = true;
    else {
      std::fprintf(
          stderr,
          "usage: msgraphs_eval_perception --run DIR [--keyframe-spacing-m 1.0] [--markdown]\n");
      return 2;
    }
  }
  if (run.empty()) {
    std::fprintf(
        stderr,
        "usage: msgraphs_eval_perception --run DIR [--keyframe-spacing-m 1.0] [--markdown]\n");
    return 2;
  }
  std::string error;
  auto world = sim::LoadWorld((fs::path(run) / "world.world").string(), error);
  if (!world) {
    std::fprintf(stderr, "eval: %s\n", error.c_str());
    return 1;
  }
  const auto t_start = std::chrono::steady_clock::now();
  const Eigen::Isometry3d T_base_lidar(Eigen::Translation3d(0, 0, 0.30));

  constexpr std::size_t kMaxPoints = 60000;
  BoundedVector<Eigen::Vector3f> scan_points(kMaxPoints), filtered(kMaxPoints), down(kMaxPoints),
      normals(kMaxPoints), world_points(kMaxPoints);
  BoundedVector<Eigen::Matrix3f> covs(kMaxPoints);
  std::vector<float> times(kMaxPoints);
  core::VoxelDownsampler voxel;
  voxel.Init(kMaxPoints);
  core::KdTree tree;
  tree.Init(kMaxPoints);
  core::PlaneExtractor planes_extractor;
  planes_extractor.Init(kMaxPoints);
  BoundedVector<core::ExtractedPlane> planes(64);
  core::FreeSpaceGridConfig grid_config;
  grid_config.width = grid_config.height = 1024;
  Eigen::Vector2d lo(1e9, 1e9), hi(-1e9, -1e9);
  for (const auto& w : world->walls) {
    lo = lo.cwiseMin(w.start).cwiseMin(w.end);
    hi = hi.cwiseMax(w.start).cwiseMax(w.end);
  }
  grid_config.origin_m = (0.5 * (lo + hi)).cast<float>() - Eigen::Vector2f(51.2f, 51.2f);
  core::FreeSpaceGrid grid;
  if (!grid.Init(grid_config)) return 1;
  std::vector<MergedWall> walls;
  std::size_t keyframes = 0, vertical_planes = 0;
  // Room-centred clouds per (robot, true room), deduplicated on a 0.1 m voxel key, for the
  // Scan Context evaluation: the room frame is the true room's rectangle.
  std::vector<sim::RoomRectangle> rects;
  for (const auto& room : world->rooms) rects.push_back(sim::MinAreaRectangle(room));
  std::map<std::pair<int, std::size_t>, std::unordered_set<std::uint64_t>> room_voxels;
  double plane_ms = 0;
  tools::PairCounts truth_of_scans;  // scans placed by the truth, and why not the others

  for (int robot = 1; robot <= 10; ++robot) {
    const fs::path dir = fs::path(run) / ("robot" + std::to_string(robot));
    if (!fs::exists(dir / "velodyne.pcap")) break;
    const tools::TruthTrajectory tum(tools::ReadTum((dir / "ground_truth.tum").string()));
    auto scans = drivers::velodyne::RecordedScans::Open((dir / "velodyne.pcap").string());
    if (!scans) return 1;
    Eigen::Isometry3d last_keyframe = Eigen::Isometry3d::Identity();
    bool have_keyframe = false;
    while (const drivers::velodyne::Scan* next = scans->Next()) {
      const auto& scan = *next;
      const double t0 = scan.start_time.seconds_since_epoch(),
                   t1 = scan.end_time.seconds_since_epoch();
      // A sweep is placed only where the truth covers both its ends (no clamping to the ends).
      const auto truth_start = tum.At(t0), truth_end = tum.At(t1);
      if (!truth_start.ok || !truth_end.ok) {
        truth_of_scans.Count(truth_start.ok ? truth_end.reason : truth_start.reason);
        continue;
      }
      ++truth_of_scans.paired;
      const Eigen::Isometry3d T_world_end = truth_end.T * T_base_lidar;
      if (have_keyframe) {
        const Eigen::Isometry3d delta = last_keyframe.inverse() * T_world_end;
        const double angle = Eigen::AngleAxisd(delta.linear()).angle();
        if (delta.translation().norm() < spacing && angle < 0.5) continue;
      }
      have_keyframe = true;
      last_keyframe = T_world_end;
      ++keyframes;
      // Deskew with the true motion over the sweep, then the usual front end.
      scan_points.clear();
      for (const auto& p : scan.points) {
        if (!scan_points.try_push_back(Eigen::Vector3f(p.x_m, p.y_m, p.z_m))) break;
        times[scan_points.size() - 1] = static_cast<float>(p.time_offset_ns * 1e-9);
      }
      const Eigen::Isometry3d T_start_end = (truth_start.T * T_base_lidar).inverse() * T_world_end;
      static_cast<void>(core::DeskewToEnd(scan_points.span(),
                                          std::span<const float>(times.data(), scan_points.size()),
                                          std::max(1e-3, t1 - t0), T_start_end));
      core::RangeFilter(scan_points.span(), 0.5f, 25.0f, filtered);
      static_cast<void>(voxel.Downsample(filtered.span(), 0.1f, down));
      if (!tree.Build(down.span())) continue;
      const Eigen::Vector3f origin(0, 0, 0);
      if (!core::EstimateCovariances(down.span(), tree, {}, normals, covs, &origin)) continue;
      const auto p0 = std::chrono::steady_clock::now();
      static_cast<void>(planes_extractor.Extract(down.span(), normals.span(), {}, planes));
      plane_ms +=
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - p0).count();
      // Free space from the full-resolution sweep, in the world frame.
      world_points.clear();
      for (const auto& p : filtered)
        static_cast<void>(
            world_points.try_push_back((T_world_end * p.cast<double>()).cast<float>()));
      grid.Integrate(T_world_end.translation().cast<float>(), world_points.span(), 0.0f);
      for (const auto& p : down) {
        const Eigen::Vector3d q = T_world_end * p.cast<double>();
        const sim::Room* room = world->RoomAt(q.head<2>(), 0);
        if (room == nullptr || q.z() < 0.05 || q.z() > 2.9)
          continue;  // walls and furniture, not floor or ceiling
        std::uint64_t key = 0;
        if (!core::VoxelKey(q.cast<float>(), 10.0f, key)) continue;
        room_voxels[{robot, static_cast<std::size_t>(room - world->rooms.data())}].insert(key);
      }
      // Walls into the world frame, as 2-D lines with their extent.
      for (const auto& plane : planes) {
        if (plane.kind != core::PlaneKind::kVertical) continue;
        ++vertical_planes;
        const Eigen::Vector3d n = T_world_end.linear() * plane.normal;
        const Eigen::Vector3d c = T_world_end * plane.centroid;
        const Eigen::Vector3d u = T_world_end.linear() * plane.basis_u;
        core::MapWall w;
        w.normal = n.head<2>().normalized();
        w.d = -w.normal.dot(c.head<2>());
        const double cu = plane.basis_u.dot(plane.centroid);
        w.a = c.head<2>() + u.head<2>() * (plane.u_min - cu);
        w.b = c.head<2>() + u.head<2>() * (plane.u_max - cu);
        if (plane.u_max - plane.u_min < 0.5 || plane.z_max - plane.z_min < 0.8)
          continue;  // furniture faces
        MergeWall(walls, w, static_cast<double>(plane.inliers));
      }
    }
  }

  // Rooms.
  std::vector<core::MapWall> map_walls;
  for (const auto& m : walls) {
    if ((m.wall.b - m.wall.a).norm() >= 1.0) map_walls.push_back(m.wall);
  }
  core::RoomSegmenter segmenter;
  if (!segmenter.Init(grid.width(), grid.height(), 1024,
                      std::max<std::size_t>(map_walls.size(), 1)))
    return 1;
  BoundedVector<core::RoomRegion> regions(1024);
  BoundedVector<core::DetectedRoom> rooms(256);
  static_cast<void>(segmenter.Segment(grid, {}, regions, map_walls));
  static_cast<void>(segmenter.DetectRooms(grid, regions.span(), map_walls, {}, rooms));

  // Compare with the truth: a detection matches the true room its centre lies in.
  std::map<std::string, bool> matched;
  std::size_t true_positive = 0, as_corridor = 0;
  double centre_error_sum = 0, centre_error_max = 0, yaw_error_sum = 0, yaw_error_max = 0;
  std::ostringstream details;
  for (const core::DetectedRoom& r : rooms) {
    const sim::Room* truth = world->RoomAt(r.centre, 0);
    const char* kind = r.kind == core::RoomKind::kRoom ? "room" : "corridor";
    if (truth == nullptr || matched[truth->id]) {
      details << "  false " << kind << " at (" << r.centre.x() << ", " << r.centre.y() << ")\n";
      continue;
    }
    matched[truth->id] = true;
    ++true_positive;
    const sim::RoomRectangle rect = sim::MinAreaRectangle(*truth);
    if (r.kind == core::RoomKind::kCorridor && rect.length_m < 3.0 * rect.width_m) ++as_corridor;
    // Corridors are located across, not along: compare the across position only.
    double centre_error = (r.centre - rect.centre).norm();
    if (r.kind == core::RoomKind::kCorridor) {
      const Eigen::Vector2d across(std::cos(r.yaw_rad), std::sin(r.yaw_rad));
      centre_error = std::fabs(across.dot(r.centre - rect.centre));
    }
    const double yaw_error = std::fabs(
        std::remainder(r.yaw_rad * 180.0 / std::numbers::pi - rect.orientation_deg, 90.0));
    centre_error_sum += centre_error;
    centre_error_max = std::max(centre_error_max, centre_error);
    yaw_error_sum += yaw_error;
    yaw_error_max = std::max(yaw_error_max, yaw_error);
    details << "  " << kind << " " << truth->id << ": centre error " << centre_error
            << " m, orientation error " << yaw_error << " deg, size " << r.size_x_m << " x "
            << r.size_y_m << " (truth " << rect.width_m << " x " << rect.length_m
            << " on centre lines)\n";
  }
  // Which true rooms were observed: at least half of their area seen free.
  std::size_t observed = 0, observed_found = 0;
  for (const sim::Room& room : world->rooms) {
    std::size_t cells = 0, free_cells = 0;
    for (int y = 0; y < grid.height(); ++y) {
      for (int x = 0; x < grid.width(); ++x) {
        if (!room.Contains(grid.CellCentre(x, y))) continue;
        ++cells;
        free_cells += grid.state(x, y) == core::FreeSpaceGrid::Cell::kFree ? 1u : 0u;
      }
    }
    if (cells > 0 && 2 * free_cells >= cells) {
      ++observed;
      observed_found += matched[room.id] ? 1u : 0u;
    }
  }
  // Scan Context between robots: each robot's cloud of a room, in that room's frame (z above the
  // floor), against every other robot's rooms. Same room should be nearest.
  struct Descriptor {
    int robot;
    std::size_t room;
    core::ScanContext sc;
  };
  std::vector<Descriptor> descriptors;
  for (const auto& [key, voxels] : room_voxels) {
    if (voxels.size() < 500) continue;  // barely seen
    const sim::RoomRectangle& rect = rects[key.second];
    const double yaw = rect.orientation_deg * std::numbers::pi / 180.0;
    const Eigen::Rotation2Dd to_room(-yaw);
    std::vector<Eigen::Vector3f> cloud;
    for (std::uint64_t v : voxels) {
      Eigen::Vector3d q;
      for (int a = 0; a < 3; ++a)
        q[a] = (static_cast<double>((v >> (21 * a)) & 0x1FFFFF) - (1 << 20) + 0.5) * 0.1;
      const Eigen::Vector2d xy = to_room * (q.head<2>() - rect.centre);
      cloud.emplace_back(static_cast<float>(xy.x()), static_cast<float>(xy.y()),
                         static_cast<float>(q.z()));
    }
    const core::ScanContextConfig sc_config;  // one absolute scale (12 m) for every room
    core::ScanContext sc;
    if (!sc.Build(cloud, sc_config)) continue;
    descriptors.push_back({key.first, key.second, sc});
  }
  std::size_t sc_queries = 0, sc_top1 = 0, sc_below = 0, sc_false_below = 0;
  double same_sum = 0, other_sum = 0;
  std::size_t same_n = 0, other_n = 0;
  for (const Descriptor& q : descriptors) {
    float best = 2.0f;
    std::size_t best_room = 0;
    bool has_same = false;
    for (const Descriptor& o : descriptors) {
      if (o.robot == q.robot) continue;
      const auto m = core::ScanContextDistance(q.sc, o.sc);
      if (!m) continue;
      if (o.room == q.room) {
        has_same = true;
        same_sum += static_cast<double>(m->distance);
        ++same_n;
        if (m->distance < 0.35f) ++sc_below;
      } else {
        other_sum += static_cast<double>(m->distance);
        ++other_n;
        if (m->distance < 0.35f) ++sc_false_below;
      }
      if (m->distance < best) {
        best = m->distance;
        best_room = o.room;
      }
    }
    if (!has_same) continue;
    ++sc_queries;
    if (best_room == q.room) ++sc_top1;
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  const double precision =
      rooms.empty() ? 0.0 : static_cast<double>(true_positive) / static_cast<double>(rooms.size());
  const double recall =
      observed == 0 ? 0.0 : static_cast<double>(observed_found) / static_cast<double>(observed);
  const double n = std::max<double>(1.0, static_cast<double>(true_positive));
  if (markdown) {
    std::printf(
        "| %s | %zu | %zu | %zu / %zu (%zu as two-wall) | %.2f | %.2f | %.3f / %.3f | %.2f / %.2f "
        "| %.1f |\n",
        world->name.c_str(), keyframes, map_walls.size(), true_positive, rooms.size(), as_corridor,
        precision, recall, centre_error_sum / n, centre_error_max, yaw_error_sum / n, yaw_error_max,
        plane_ms / std::max<double>(1, static_cast<double>(keyframes)));
  } else {
    std::printf(
        "world %s: %zu keyframes, %zu vertical planes, %zu merged walls, %zu regions, %zu "
        "rooms/corridors detected\n",
        world->name.c_str(), keyframes, vertical_planes, map_walls.size(), regions.size(),
        rooms.size());
    std::printf("%s", details.str().c_str());
    if (std::getenv("MSGRAPHS_EVAL_WALLS") != nullptr) {
      for (const auto& w : map_walls) {
        std::printf("  wall %u: n (%.2f, %.2f) d %.2f from (%.2f, %.2f) to (%.2f, %.2f)\n", w.id,
                    w.normal.x(), w.normal.y(), w.d, w.a.x(), w.a.y(), w.b.x(), w.b.y());
      }
    }
    std::printf(
        "precision %.2f (%zu of %zu detections are true rooms; %zu rooms found by one wall pair "
        "only), recall %.2f (%zu of %zu observed rooms)\n",
        precision, true_positive, rooms.size(), as_corridor, recall, observed_found, observed);
    std::printf(
        "centre error mean %.3f m, max %.3f m; orientation error mean %.2f deg, max %.2f deg\n",
        centre_error_sum / n, centre_error_max, yaw_error_sum / n, yaw_error_max);
    std::printf(
        "scan context across robots: %zu room descriptors; same room mean distance %.3f (%zu "
        "pairs, %zu below SC_th 0.35), "
        "different rooms %.3f (%zu pairs, %zu below 0.35); nearest is the same room for %zu of "
        "%zu\n",
        descriptors.size(), same_sum / std::max<double>(1.0, static_cast<double>(same_n)), same_n,
        sc_below, other_sum / std::max<double>(1.0, static_cast<double>(other_n)), other_n,
        sc_false_below, sc_top1, sc_queries);
    std::printf("truth placed %zu of %zu scans (unpaired: %s)\n", truth_of_scans.paired,
                truth_of_scans.total(), truth_of_scans.DescribeUnpaired().c_str());
    std::printf("wall extraction %.1f ms per keyframe; total %.1f s\n",
                plane_ms / std::max<double>(1, static_cast<double>(keyframes)), seconds);
  }
  return 0;
}
