// SPDX-License-Identifier: MIT
// msgraphs_fleet_report: what a fleet of msgraphs_node processes produced, gathered into one
// folder a user opens in the tools of the field, with a short report per robot.
//
//   msgraphs_fleet_report --out NODES --dest DIR [--run RUN] [--view 1] [--offset K=SECONDS]...
//                         [--max-dt-s S] [--expect-merged]
//
// NODES/robotK/ holds each node's outputs (keyframes.tum, origins.csv, map.pcd,
// collab_graph.csv, stats.txt); RUN/robotK/ground_truth.tum the simulator's truth (optional:
// without it no ATE). --offset K=S: robot K's node stamped its inputs on arrival (live UDP), S
// seconds after the recording's clock (msgraphs_replay prints it); its keyframes are brought
// back to the recording's clock. Every keyframe is scored against its robot's truth interpolated
// at its stamp (tools/truth_pairing.hpp; --max-dt-s S: optional stricter limit, a truth sample
// within S seconds); keyframes without truth are counted with the reason. Writes, in robot V's
// (--view) map frame:
//   DIR/robotK.tum          every robot's keyframes (TUM, recording clock: evo reads them)
//   DIR/merged_map.pcd      every robot's map.pcd laid out by V's estimate of its origin
//   DIR/collab_graph.svg    walls, rooms, room matches and every trajectory, seen from above
//   DIR/report.txt          the report printed on stdout
// Exit 1 when an input is missing (a robot of RUN without keyframes.tum included), with --run
// when a robot's own ATE or V's aggregated ATE cannot be computed (a robot without truth at its
// keyframes is reported, never left out), or with --expect-merged when V did not merge every
// robot.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <unordered_set>
#include <vector>

#include "msgraphs/runtime/outputs/pcd_file.hpp"
#include "msgraphs/tools/aggregated_ate.hpp"
#include "msgraphs/tools/ate.hpp"
#include "msgraphs/tools/truth_pairing.hpp"
#include "msgraphs/tools/tum.hpp"

namespace {

namespace fs = std::filesystem;
using msgraphs::tools::StampedPose;

struct Options {
  std::string nodes, dest, run;
  int view = 1;
  std::map<int, double> offset_s;
  double max_dt_s = 0;  ///< optional stricter pairing limit; 0: none
  bool expect_merged = false;
};

struct Wall {
  int robot;
  Eigen::Vector2d a, b;
};
struct Room {
  int robot, id;
  Eigen::Vector2d centre;
  double yaw, size_x, size_y;
  bool corridor;
};
struct Match {
  int robot_a, room_a, robot_b, room_b;
};
struct Origin {
  bool merged = false;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
};
struct CollabGraph {
  std::map<int, Origin> origins;
  std::vector<Wall> walls;
  std::vector<Room> rooms;
  std::vector<Match> matches;
};

std::vector<std::string> SplitCsv(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream s(line);
  for (std::string item; std::getline(s, item, ',');) out.push_back(item);
  return out;
}

bool ReadCollabGraph(const fs::path& path, CollabGraph& g) {
  std::ifstream in(path);
  if (!in) return false;
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    const auto f = SplitCsv(line);
    auto num = [&](std::size_t i) { return i < f.size() ? std::atof(f[i].c_str()) : 0.0; };
    if (f[0] == "origin" && f.size() == 10) {
      Origin o;
      o.merged = num(2) != 0;
      o.T.linear() =
          Eigen::Quaterniond(num(9), num(6), num(7), num(8)).normalized().toRotationMatrix();
      o.T.translation() << num(3), num(4), num(5);
      g.origins[static_cast<int>(num(1))] = o;
    } else if (f[0] == "wall" && f.size() == 11) {
      g.walls.push_back({static_cast<int>(num(1)), {num(3), num(4)}, {num(5), num(6)}});
    } else if (f[0] == "room" && f.size() == 10) {
      g.rooms.push_back({static_cast<int>(num(1)),
                         static_cast<int>(num(2)),
                         {num(3), num(4)},
                         num(6),
                         num(7),
                         num(8),
                         num(9) != 0});
    } else if (f[0] == "match" && f.size() == 5) {
      g.matches.push_back({static_cast<int>(num(1)), static_cast<int>(num(2)),
                           static_cast<int>(num(3)), static_cast<int>(num(4))});
    }
  }
  return true;
}

std::map<std::string, double> ReadStats(const fs::path& path) {
  std::map<std::string, double> out;
  std::ifstream in(path);
  std::string key;
  double value;
  while (in >> key >> value) out[key] = value;
  return out;
}

const char* Colour(int robot) {
  static const std::array<const char*, 8> colours = {"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728",
                                                     "#9467bd", "#8c564b", "#e377c2", "#7f7f7f"};
  return colours[static_cast<std::size_t>(robot - 1) % colours.size()];
}

// Where robots' walls coincide (merged well) each must stay visible: robot 1's widest.
double WallWidth(int robot) { return std::max(1.5, 6.5 - 1.75 * robot); }

// Top-down picture of the collaborative S-Graph in the view's frame: 1 m = `scale` px, x right,
// y up; walls per robot's colour, rooms as their wall-to-wall boxes, matched rooms joined.
bool WriteSvg(const fs::path& path,
              int view,
              const CollabGraph& g,
              const std::map<int, std::vector<StampedPose>>& trajectories) {
  double x0 = 1e9, y0 = 1e9, x1 = -1e9, y1 = -1e9;
  auto grow = [&](const Eigen::Vector2d& p) {
    x0 = std::min(x0, p.x()), y0 = std::min(y0, p.y());
    x1 = std::max(x1, p.x()), y1 = std::max(y1, p.y());
  };
  for (const Wall& w : g.walls) grow(w.a), grow(w.b);
  for (const auto& [robot, poses] : trajectories) {
    for (const StampedPose& p : poses) grow(p.T.translation().head<2>());
  }
  if (x0 > x1) return false;
  const double scale = 20, margin = 2;
  x0 -= margin, y0 -= margin, x1 += margin, y1 += margin;
  const int width = static_cast<int>((x1 - x0) * scale),
            height = static_cast<int>((y1 - y0) * scale);
  auto X = [&](double x) { return (x - x0) * scale; };
  auto Y = [&](double y) { return (y1 - y) * scale; };
  std::ofstream out(path);
  out.precision(5);
  const int legend = 24 * static_cast<int>(trajectories.size() + 1);
  out << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width << "\" height=\""
      << height + legend << "\" font-family=\"sans-serif\" font-size=\"13\">\n"
      << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  // 1 m grid every 5 m.
  out << "<g stroke=\"#eeeeee\" stroke-width=\"1\">\n";
  for (double x = std::ceil(x0 / 5) * 5; x <= x1; x += 5)
    out << "<line x1=\"" << X(x) << "\" y1=\"0\" x2=\"" << X(x) << "\" y2=\"" << height << "\"/>\n";
  for (double y = std::ceil(y0 / 5) * 5; y <= y1; y += 5)
    out << "<line x1=\"0\" y1=\"" << Y(y) << "\" x2=\"" << width << "\" y2=\"" << Y(y) << "\"/>\n";
  out << "</g>\n";
  for (const Room& r : g.rooms) {
    // The room's box, wall to wall, in its own orientation (a corridor has no length: none).
    if (r.corridor) continue;
    const double sx = r.size_x / 2, sy = r.size_y / 2;
    const Eigen::Rotation2Dd R(r.yaw);
    out << "<polygon fill=\"" << Colour(r.robot)
        << "\" fill-opacity=\"0.08\" stroke=\"none\" points=\"";
    for (const auto& c : {Eigen::Vector2d(-sx, -sy), Eigen::Vector2d(sx, -sy),
                          Eigen::Vector2d(sx, sy), Eigen::Vector2d(-sx, sy)}) {
      const Eigen::Vector2d p = r.centre + R * c;
      out << X(p.x()) << ',' << Y(p.y()) << ' ';
    }
    out << "\"/>\n";
  }
  std::vector<Wall> walls = g.walls;
  std::stable_sort(walls.begin(), walls.end(),
                   [](const Wall& a, const Wall& b) { return a.robot < b.robot; });
  for (const Wall& w : walls) {
    out << "<line x1=\"" << X(w.a.x()) << "\" y1=\"" << Y(w.a.y()) << "\" x2=\"" << X(w.b.x())
        << "\" y2=\"" << Y(w.b.y()) << "\" stroke=\"" << Colour(w.robot) << "\" stroke-width=\""
        << WallWidth(w.robot) << "\" stroke-linecap=\"round\"/>\n";
  }
  for (const auto& [robot, poses] : trajectories) {
    out << "<polyline fill=\"none\" stroke=\"" << Colour(robot)
        << "\" stroke-width=\"1.5\" stroke-dasharray=\"4 2\" points=\"";
    for (const StampedPose& p : poses)
      out << X(p.T.translation().x()) << ',' << Y(p.T.translation().y()) << ' ';
    out << "\"/>\n";
    if (!poses.empty()) {
      const Eigen::Vector3d s = poses.front().T.translation();
      out << "<circle cx=\"" << X(s.x()) << "\" cy=\"" << Y(s.y()) << "\" r=\"6\" fill=\""
          << Colour(robot) << "\"/><text x=\"" << X(s.x()) + 8 << "\" y=\"" << Y(s.y()) - 8
          << "\">start " << robot << "</text>\n";
    }
  }
  auto find_room = [&](int robot, int id) -> const Room* {
    for (const Room& r : g.rooms) {
      if (r.robot == robot && r.id == id) return &r;
    }
    return nullptr;
  };
  for (const Match& m : g.matches) {
    const Room* a = find_room(m.robot_a, m.room_a);
    const Room* b = find_room(m.robot_b, m.room_b);
    if (a == nullptr || b == nullptr) continue;
    out << "<line x1=\"" << X(a->centre.x()) << "\" y1=\"" << Y(a->centre.y()) << "\" x2=\""
        << X(b->centre.x()) << "\" y2=\"" << Y(b->centre.y())
        << "\" stroke=\"black\" stroke-width=\"6\" stroke-opacity=\"0.35\"/>\n";
  }
  for (const Room& r : g.rooms) {
    out << "<rect x=\"" << X(r.centre.x()) - 4 << "\" y=\"" << Y(r.centre.y()) - 4
        << "\" width=\"8\" height=\"8\" fill=\"" << Colour(r.robot)
        << "\" stroke=\"black\" stroke-width=\"0.5\"/>\n";
  }
  int row = 0;
  auto legend_line = [&](const char* colour, const std::string& text) {
    const int y = height + 18 + 24 * row++;
    out << "<rect x=\"10\" y=\"" << y - 10 << "\" width=\"24\" height=\"6\" fill=\"" << colour
        << "\"/><text x=\"42\" y=\"" << y << "\">" << text << "</text>\n";
  };
  for (const auto& [robot, poses] : trajectories) {
    legend_line(Colour(robot),
                "robot " + std::to_string(robot) +
                    ": walls (solid), rooms (squares, shaded boxes), keyframes (dashed)" +
                    (robot == view ? " - the reference frame" : ""));
  }
  legend_line("#a6a6a6", "accepted room matches (grey bars); grid 5 m; seen from above in robot " +
                             std::to_string(view) + "'s map frame");
  out << "</svg>\n";
  return static_cast<bool>(out);
}

bool ParseOptions(int argc, char** argv, Options& o) {
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> const char* { return i + 1 < argc ? argv[++i] : nullptr; };
    const char* v = nullptr;
    if (a == "--out" && (v = next()))
      o.nodes = v;
    else if (a == "--dest" && (v = next()))
      o.dest = v;
    else if (a == "--run" && (v = next()))
      o.run = v;
    else if (a == "--view" && (v = next()))
      o.view = std::atoi(v);
    else if (a == "--max-dt-s" && (v = next())) {
      o.max_dt_s = std::atof(v);
      if (!(o.max_dt_s >= 0)) return false;
    } else if (a == "--expect-merged")
      o.expect_merged = true;
    else if (a == "--offset" && (v = next())) {
      const std::string s = v;
      const auto eq = s.find('=');
      if (eq == std::string::npos) return false;
      o.offset_s[std::atoi(s.substr(0, eq).c_str())] = std::atof(s.substr(eq + 1).c_str());
    } else {
      return false;
    }
  }
  return !o.nodes.empty() && !o.dest.empty() && o.view > 0;
}

// printf to stdout and into the report file's text.
__attribute__((format(printf, 2, 3))) void Say(std::string& report, const char* format, ...) {
  char line[4096];
  va_list args;
  va_start(args, format);
  std::vsnprintf(line, sizeof line, format, args);
  va_end(args);
  report += line;
  std::fputs(line, stdout);
}

std::string Kb(double bytes) {
  char b[32];
  std::snprintf(b, sizeof b, "%.1f kB", bytes / 1e3);
  return b;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  if (!ParseOptions(argc, argv, o)) {
    std::fprintf(stderr,
                 "usage: msgraphs_fleet_report --out NODES --dest DIR [--run RUN] [--view 1]\n"
                 "                             [--offset K=SECONDS]... [--max-dt-s S] "
                 "[--expect-merged]\n");
    return 2;
  }
  std::error_code ec;
  fs::create_directories(o.dest, ec);
  std::map<int, std::vector<StampedPose>> keyframes;
  std::map<int, msgraphs::tools::TruthTrajectory> truth;
  msgraphs::tools::PairingConfig pairing;
  pairing.max_dt_s = o.max_dt_s;
  bool failed = false;
  for (int k = 1; k <= 64; ++k) {
    const fs::path kf = fs::path(o.nodes) / ("robot" + std::to_string(k)) / "keyframes.tum";
    const fs::path gt = fs::path(o.run) / ("robot" + std::to_string(k)) / "ground_truth.tum";
    const bool have_truth = !o.run.empty() && fs::exists(gt);
    if (!fs::exists(kf)) {
      if (have_truth) {
        // A robot of the mission whose node wrote nothing: listed, never silently absent.
        std::printf("robot %d: no keyframes.tum in %s (its node wrote nothing)\n", k,
                    kf.parent_path().c_str());
        failed = true;
      }
      continue;
    }
    keyframes[k] = msgraphs::tools::ReadTum(kf.string());
    const double offset = o.offset_s.count(k) ? o.offset_s[k] : 0.0;
    for (StampedPose& p : keyframes[k]) p.t -= offset;
    if (have_truth)
      truth.emplace(
          k, msgraphs::tools::TruthTrajectory(msgraphs::tools::ReadTum(gt.string()), pairing));
  }
  if (!keyframes.count(o.view)) {
    std::fprintf(stderr, "fleet_report: no keyframes.tum of robot %d in %s\n", o.view,
                 o.nodes.c_str());
    return 1;
  }
  CollabGraph graph;
  const fs::path view_dir = fs::path(o.nodes) / ("robot" + std::to_string(o.view));
  if (!ReadCollabGraph(view_dir / "collab_graph.csv", graph)) {
    std::fprintf(stderr, "fleet_report: cannot read %s\n", (view_dir / "collab_graph.csv").c_str());
    return 1;
  }
  std::string report;
  // Each robot alone: its own map against its own truth, and what its node reported.
  std::map<int, Eigen::Isometry3d> T_world_map;
  for (const auto& [k, poses] : keyframes) {
    const auto stats = ReadStats(fs::path(o.nodes) / ("robot" + std::to_string(k)) / "stats.txt");
    auto st = [&](const char* key) { return stats.count(key) ? stats.at(key) : 0.0; };
    std::string ate = "no ground truth", pairs;
    if (truth.count(k)) {
      const auto a = msgraphs::tools::ComputeAte(poses, truth.at(k));
      if (a.ok) {
        T_world_map[k] = a.T_truth_estimate;
        char b[96];
        std::snprintf(b, sizeof b, "ATE %.1f cm over %zu keyframes", a.rmse * 100, a.poses());
        ate = b;
      } else {
        ate = std::string("ATE not computed: ") + a.error;
        failed = true;
      }
      pairs = "  truth: paired at " + std::to_string(a.pairs.paired) + " of " +
              std::to_string(poses.size()) + " keyframes (unpaired: " + a.pairs.DescribeUnpaired() +
              ")\n";
    } else if (!o.run.empty()) {
      failed = true;  // asked to score against the truth, and this robot has none
    }
    Say(report, "robot %d: %s; %.0f walls, %.0f rooms mapped; merged %.0f of %.0f other robots\n",
        k, ate.c_str(), st("walls"), st("rooms"), st("merged"), st("peers"));
    if (!pairs.empty()) Say(report, "%s", pairs.c_str());
    const double rejected = st("matches_rejected_fine") + st("matches_rejected_anchored") +
                            st("matches_rejected_consistency");
    Say(report,
        "  room matches: %.0f accepted, %.0f rejected (%.0f by fine alignment, %.0f against the "
        "merged estimate, %.0f outside the consistent set) of %.0f proposed\n",
        st("matches_accepted"), rejected, st("matches_rejected_fine"),
        st("matches_rejected_anchored"), st("matches_rejected_consistency"),
        st("matches_proposed"));
    Say(report,
        "  sent: graph %s, descriptors %s, cloud requests %s, room clouds %s, free space %s, place "
        "requests %s, place clouds %s (%s in all)\n",
        Kb(st("sent_graph_bytes")).c_str(), Kb(st("sent_descriptors_bytes")).c_str(),
        Kb(st("sent_requests_bytes")).c_str(), Kb(st("sent_clouds_bytes")).c_str(),
        Kb(st("sent_free_space_bytes")).c_str(), Kb(st("sent_place_requests_bytes")).c_str(),
        Kb(st("sent_place_clouds_bytes")).c_str(),
        Kb(st("sent_graph_bytes") + st("sent_descriptors_bytes") + st("sent_requests_bytes") +
           st("sent_clouds_bytes") + st("sent_free_space_bytes") + st("sent_place_requests_bytes") +
           st("sent_place_clouds_bytes"))
            .c_str());
    Say(report,
        "  node: keyframe %.1f ms p50, %.1f ms p99; scan queue peak %.0f, %.0f scans dropped; "
        "peak RSS %.0f MB\n",
        st("keyframe_p50_ms"), st("keyframe_p99_ms"), st("scan_queue_peak"), st("scans_dropped"),
        st("peak_rss_mb"));
  }

  // Robot V's view: every robot it merged, in its frame; every other one listed as missing.
  std::map<int, std::vector<StampedPose>> in_view;
  msgraphs::tools::AggregatedAteBuilder aggregated;
  std::size_t merged = 0;
  std::string origin_errors;
  for (const auto& [k, poses] : keyframes) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    if (k != o.view) {
      const auto it = graph.origins.find(k);
      if (it == graph.origins.end() || !it->second.merged) {
        aggregated.AddNotMerged(k);
        continue;
      }
      T = it->second.T;
      char b[128];
      if (T_world_map.count(k) && T_world_map.count(o.view)) {
        const Eigen::Isometry3d e = (T_world_map[o.view].inverse() * T_world_map[k]).inverse() * T;
        std::snprintf(b, sizeof b, "; robot %d's origin off by %.1f cm, %.2f deg", k,
                      e.translation().norm() * 100,
                      Eigen::AngleAxisd(e.linear()).angle() * 180.0 / M_PI);
      } else {
        std::snprintf(b, sizeof b, "; robot %d's origin not checked (no truth alignment)", k);
      }
      if (!o.run.empty()) origin_errors += b;
    }
    ++merged;
    auto& out = in_view[k];
    for (const StampedPose& p : poses) out.push_back({p.t, T * p.T});
    aggregated.AddMerged(k, out, truth.count(k) ? &truth.at(k) : nullptr);
    msgraphs::tools::WriteTum((fs::path(o.dest) / ("robot" + std::to_string(k) + ".tum")).string(),
                              out);
  }
  if (!o.run.empty()) {
    const msgraphs::tools::AggregatedAte a = aggregated.Finish();
    if (a.ok()) {
      Say(report,
          "robot %d's view: %zu of %zu robots in its frame; aggregated ATE %.1f cm over %zu "
          "keyframes%s\n  (%s)\n",
          o.view, merged, keyframes.size(), a.ate.rmse * 100, a.ate.poses(), origin_errors.c_str(),
          a.Describe().c_str());
    } else {
      Say(report,
          "robot %d's view: %zu of %zu robots in its frame; aggregated ATE FAILED: %s%s\n"
          "  (%s)\n",
          o.view, merged, keyframes.size(), a.failure().c_str(), origin_errors.c_str(),
          a.Describe().c_str());
      failed = true;
    }
  } else {
    Say(report, "robot %d's view: %zu of %zu robots in its frame\n", o.view, merged,
        keyframes.size());
  }

  // The merged map: every merged robot's map.pcd in V's frame, one point per 5 cm voxel.
  std::vector<Eigen::Vector3f> points;
  std::unordered_set<std::uint64_t> voxels;
  std::size_t maps = 0;
  for (const auto& [k, poses] : in_view) {
    const fs::path pcd = fs::path(o.nodes) / ("robot" + std::to_string(k)) / "map.pcd";
    auto cloud = msgraphs::runtime::ReadPcd(pcd.string());
    if (!cloud) {
      std::fprintf(stderr, "fleet_report: %s: %s\n", pcd.c_str(), cloud.error().detail);
      continue;
    }
    ++maps;
    const Eigen::Isometry3f T =
        (k == o.view ? Eigen::Isometry3d::Identity() : graph.origins[k].T).cast<float>();
    for (const Eigen::Vector3f& p : *cloud) {
      const Eigen::Vector3f q = T * p;
      if (voxels.insert(msgraphs::runtime::VoxelKey(q, 0.05f)).second) points.push_back(q);
    }
  }
  const fs::path merged_pcd = fs::path(o.dest) / "merged_map.pcd";
  if (auto s = msgraphs::runtime::WritePcd(merged_pcd.string(), points); !s) {
    std::fprintf(stderr, "fleet_report: cannot write %s: %s\n", merged_pcd.c_str(),
                 s.error().detail);
    return 1;
  }
  const fs::path svg = fs::path(o.dest) / "collab_graph.svg";
  if (!WriteSvg(svg, o.view, graph, in_view)) {
    std::fprintf(stderr, "fleet_report: cannot draw %s\n", svg.c_str());
    return 1;
  }
  Say(report,
      "wrote %s: %zu robots' TUM keyframes, merged_map.pcd (%zu maps, %zu points), "
      "collab_graph.svg (%zu walls, %zu rooms, %zu room matches)\n",
      o.dest.c_str(), in_view.size(), maps, points.size(), graph.walls.size(), graph.rooms.size(),
      graph.matches.size());
  std::ofstream(fs::path(o.dest) / "report.txt") << report;
  if (o.expect_merged && merged != keyframes.size()) return 1;
  return failed ? 1 : 0;
}
