// SPDX-License-Identifier: MIT
#include "shared_truth.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <set>

namespace msgraphs::sim {
namespace {

std::string Join(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : ";") + x;
  return s;
}

}  // namespace

std::vector<std::string> RoomsInside(const World& world, int level, const Trajectory& trajectory) {
  std::vector<bool> inside(world.rooms.size(), false);
  const double step_s = 0.1;
  const auto n = static_cast<std::int64_t>(std::floor(trajectory.duration_s() / step_s));
  for (std::int64_t k = 0; k <= n; ++k) {
    const PlanarPose p = trajectory.Planar(static_cast<double>(k) * step_s);
    for (std::size_t r = 0; r < world.rooms.size(); ++r) {
      if (!inside[r] && world.rooms[r].level == level && world.rooms[r].Contains({p.x, p.y}))
        inside[r] = true;
    }
  }
  std::vector<std::string> out;
  for (std::size_t r = 0; r < world.rooms.size(); ++r) {
    if (inside[r]) out.push_back(world.rooms[r].id);
  }
  return out;
}

std::vector<PairSharing> ComputeSharing(const World& world,
                                        int level,
                                        const std::vector<RobotTruth>& robots,
                                        std::uint32_t min_hits) {
  std::vector<std::vector<std::string>> inside;
  for (const RobotTruth& r : robots) inside.push_back(RoomsInside(world, level, *r.trajectory));
  auto has = [](const std::vector<std::string>& v, const std::string& s) {
    return std::find(v.begin(), v.end(), s) != v.end();
  };
  std::vector<PairSharing> pairs;
  for (std::size_t a = 0; a < robots.size(); ++a) {
    for (std::size_t b = a + 1; b < robots.size(); ++b) {
      PairSharing p;
      p.robot_a = robots[a].id;
      p.robot_b = robots[b].id;
      for (const auto& r : inside[a]) {
        if (has(inside[b], r)) p.rooms_both_inside.push_back(r);
      }
      for (const Room& room : world.rooms) {
        if (has(robots[a].peeked, room.id) && !has(inside[a], room.id) && has(inside[b], room.id))
          p.peeked_by_a_entered_by_b.push_back(room.id);
        if (has(robots[b].peeked, room.id) && !has(inside[b], room.id) && has(inside[a], room.id))
          p.peeked_by_b_entered_by_a.push_back(room.id);
      }
      const WallVisibility& va = *robots[a].visibility;
      const WallVisibility& vb = *robots[b].visibility;
      Eigen::Matrix2d M = Eigen::Matrix2d::Zero();
      for (std::size_t w = 0; w < va.walls() && w < world.walls.size(); ++w) {
        const Eigen::Vector2d n = world.walls[w].normal();  // either face: n n^T is the same
        for (const int face : {1, -1}) {
          bool any = false;
          for (int bin = 0; bin < va.bins(w); ++bin) {
            if (va.hits(w, face, bin) < min_hits || vb.hits(w, face, bin) < min_hits) continue;
            const double len = va.solid_m(w, bin);
            p.shared_wall_m += len;
            M += len * n * n.transpose();
            any = any || len > 0;
          }
          p.shared_faces += any ? 1 : 0;
        }
      }
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(M);
      p.eig_min_m = std::max(0.0, eig.eigenvalues()(0));
      p.eig_max_m = std::max(0.0, eig.eigenvalues()(1));
      const Eigen::Vector2d major = eig.eigenvectors().col(1);
      double deg = std::atan2(major.y(), major.x()) * 180.0 / std::numbers::pi;
      deg = std::fmod(deg + 360.0, 180.0);
      p.major_normal_deg = p.eig_max_m > 0 ? deg : 0.0;
      pairs.push_back(std::move(p));
    }
  }
  return pairs;
}

bool WriteVisibilityCsv(const std::vector<RobotTruth>& robots, const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) return false;
  std::fprintf(f, "robot,wall,face,bin,from_m,to_m,solid_m,hits\n");
  for (const RobotTruth& r : robots) {
    const WallVisibility& v = *r.visibility;
    const World& world = *v.world();
    for (std::size_t w = 0; w < v.walls(); ++w) {
      for (const int face : {1, -1}) {
        for (int bin = 0; bin < v.bins(w); ++bin) {
          const std::uint32_t hits = v.hits(w, face, bin);
          if (hits == 0) continue;
          std::fprintf(f, "%d,%s,%c,%d,%.2f,%.2f,%.3f,%u\n", r.id, world.walls[w].id.c_str(),
                       face > 0 ? 'a' : 'b', bin, bin * WallVisibility::kBinM,
                       std::min(world.walls[w].length(), (bin + 1) * WallVisibility::kBinM),
                       v.solid_m(w, bin), hits);
        }
      }
    }
  }
  return std::fclose(f) == 0;
}

bool WriteSharedCsv(const std::vector<PairSharing>& pairs,
                    std::uint32_t min_hits,
                    const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) return false;
  std::fprintf(
      f,
      "robot_a,robot_b,rooms_both_inside,peeked_by_a_entered_by_b,peeked_by_b_entered_by_a,"
      "shared_wall_m,shared_faces,eig_min_m,eig_max_m,major_normal_deg,min_hits\n");
  for (const PairSharing& p : pairs) {
    std::fprintf(f, "%d,%d,%s,%s,%s,%.2f,%d,%.3f,%.3f,%.1f,%u\n", p.robot_a, p.robot_b,
                 Join(p.rooms_both_inside).c_str(), Join(p.peeked_by_a_entered_by_b).c_str(),
                 Join(p.peeked_by_b_entered_by_a).c_str(), p.shared_wall_m, p.shared_faces,
                 p.eig_min_m, p.eig_max_m, p.major_normal_deg, min_hits);
  }
  return std::fclose(f) == 0;
}

}  // namespace msgraphs::sim
