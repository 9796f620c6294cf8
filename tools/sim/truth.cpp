// SPDX-License-Identifier: MIT
#include "truth.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <numbers>

namespace msgraphs::sim {

bool WriteTum(const Trajectory& trajectory,
              const RobotClocks& clocks,
              double rate_hz,
              const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) return false;
  const auto n = static_cast<std::int64_t>(std::floor(trajectory.duration_s() * rate_hz));
  for (std::int64_t k = 0; k <= n; ++k) {
    const double t = static_cast<double>(k) / rate_hz;
    const Eigen::Isometry3d T = trajectory.Pose(t);
    const Eigen::Quaterniond q(T.linear());
    std::fprintf(f, "%.6f %.6f %.6f %.6f %.9f %.9f %.9f %.9f\n",
                 clocks.Host(t).seconds_since_epoch(), T.translation().x(), T.translation().y(),
                 T.translation().z(), q.x(), q.y(), q.z(), q.w());
  }
  return std::fclose(f) == 0;
}

bool WriteStartPose(const RobotPlan& plan, const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) return false;
  const Eigen::Isometry3d T = plan.trajectory.Pose(0.0);
  const Eigen::Quaterniond q(T.linear());
  std::fprintf(
      f,
      "# T_world_base at the robot's start: x y z qx qy qz qw, then yaw in degrees and the room\n");
  std::fprintf(f, "%.6f %.6f %.6f %.9f %.9f %.9f %.9f %.4f %s\n", T.translation().x(),
               T.translation().y(), T.translation().z(), q.x(), q.y(), q.z(), q.w(),
               plan.start.yaw * 180.0 / std::numbers::pi, plan.start_room.c_str());
  return std::fclose(f) == 0;
}

bool WriteWallsCsv(const World& world, const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) return false;
  // Each face as a plane n.p + d = 0 with n pointing out of the wall (into the room it faces).
  std::fprintf(f,
               "id,level,x1,y1,x2,y2,thickness_m,height_m,doors,face_a_nx,face_a_ny,face_a_d,face_"
               "b_nx,face_b_ny,face_b_d\n");
  for (const Wall& w : world.walls) {
    const Eigen::Vector2d n = w.normal();
    const Eigen::Vector2d pa = w.start + n * (0.5 * w.thickness_m),
                          pb = w.start - n * (0.5 * w.thickness_m);
    std::fprintf(f, "%s,%d,%.4f,%.4f,%.4f,%.4f,%.3f,%.3f,%zu,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f\n",
                 w.id.c_str(), w.level, w.start.x(), w.start.y(), w.end.x(), w.end.y(),
                 w.thickness_m, w.height_m, w.doors.size(), n.x(), n.y(), -n.dot(pa), -n.x(),
                 -n.y(), n.dot(pb));
  }
  return std::fclose(f) == 0;
}

RoomRectangle MinAreaRectangle(const Room& room) {
  RoomRectangle best;
  double best_area = std::numeric_limits<double>::infinity();
  const auto& p = room.polygon;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Eigen::Vector2d e = (p[(i + 1) % p.size()] - p[i]).normalized();
    const Eigen::Vector2d n(-e.y(), e.x());
    double a0 = 1e18, a1 = -1e18, b0 = 1e18, b1 = -1e18;
    for (const auto& q : p) {
      a0 = std::min(a0, e.dot(q));
      a1 = std::max(a1, e.dot(q));
      b0 = std::min(b0, n.dot(q));
      b1 = std::max(b1, n.dot(q));
    }
    const double area = (a1 - a0) * (b1 - b0);
    if (area < best_area - 1e-9) {
      best_area = area;
      double angle = std::atan2(e.y(), e.x()) * 180.0 / std::numbers::pi;
      double w = a1 - a0, l = b1 - b0;
      if (w > l) {
        std::swap(w, l);
        angle += 90.0;
      }
      angle = std::fmod(std::fmod(angle, 180.0) + 180.0, 180.0);
      best = {angle, w, l, e * (0.5 * (a0 + a1)) + n * (0.5 * (b0 + b1))};
    }
  }
  return best;
}

bool WriteRoomsCsv(const World& world, const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) return false;
  std::fprintf(f,
               "id,name,level,centre_x,centre_y,area_m2,orientation_deg,width_m,length_m,vertices,"
               "polygon\n");
  for (const Room& r : world.rooms) {
    const RoomRectangle rect = MinAreaRectangle(r);
    std::fprintf(f, "%s,%s,%d,%.4f,%.4f,%.3f,%.3f,%.4f,%.4f,%zu,", r.id.c_str(), r.name.c_str(),
                 r.level, rect.centre.x(), rect.centre.y(), r.Area(), rect.orientation_deg,
                 rect.width_m, rect.length_m, r.polygon.size());
    for (std::size_t i = 0; i < r.polygon.size(); ++i) {
      std::fprintf(f, "%s%.4f %.4f", i > 0 ? ";" : "", r.polygon[i].x(), r.polygon[i].y());
    }
    std::fprintf(f, "\n");
  }
  return std::fclose(f) == 0;
}

bool WriteSvg(const World& world, const Mission* mission, int level, const std::string& path) {
  Eigen::Vector2d lo(1e9, 1e9), hi(-1e9, -1e9);
  for (const Wall& w : world.walls) {
    lo = lo.cwiseMin(w.start).cwiseMin(w.end);
    hi = hi.cwiseMax(w.start).cwiseMax(w.end);
  }
  lo -= Eigen::Vector2d(1, 1);
  hi += Eigen::Vector2d(1, 1);
  const double scale = 900.0 / std::max(hi.x() - lo.x(), hi.y() - lo.y());  // px per metre
  const double width = (hi.x() - lo.x()) * scale, height = (hi.y() - lo.y()) * scale;
  auto X = [&](double x) { return (x - lo.x()) * scale; };
  auto Y = [&](double y) { return (hi.y() - y) * scale; };  // y up
  std::ofstream out(path);
  if (!out) return false;
  out.setf(std::ios::fixed);
  out.precision(1);
  out << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width << "\" height=\""
      << height + 30 << "\" viewBox=\"0 0 " << width << " " << height + 30
      << "\" font-family=\"sans-serif\">\n"
      << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  for (const Room& r : world.rooms) {
    if (r.level != level) continue;
    out << "<polygon fill=\"#eef3fa\" stroke=\"#b8c6d8\" stroke-width=\"1\" points=\"";
    for (const auto& p : r.polygon) out << X(p.x()) << "," << Y(p.y()) << " ";
    const Eigen::Vector2d c = r.Centroid();
    out << "\"/>\n<text x=\"" << X(c.x()) << "\" y=\"" << Y(c.y())
        << "\" font-size=\"11\" fill=\"#5a6b80\" "
        << "text-anchor=\"middle\">" << r.id << "</text>\n";
  }
  for (const Box& b : world.boxes) {
    if (b.level != level) continue;
    const Eigen::Rotation2Dd R(b.yaw_rad);
    out << "<polygon fill=\"#d9c7a7\" stroke=\"#8a7350\" stroke-width=\"0.8\" points=\"";
    for (const auto& corner : {Eigen::Vector2d(-1, -1), Eigen::Vector2d(1, -1),
                               Eigen::Vector2d(1, 1), Eigen::Vector2d(-1, 1)}) {
      const Eigen::Vector2d p = b.centre + R * Eigen::Vector2d(corner.x() * 0.5 * b.size_m.x(),
                                                               corner.y() * 0.5 * b.size_m.y());
      out << X(p.x()) << "," << Y(p.y()) << " ";
    }
    out << "\"/>\n";
  }
  for (const Cylinder& c : world.cylinders) {
    if (c.level != level) continue;
    out << "<circle cx=\"" << X(c.centre.x()) << "\" cy=\"" << Y(c.centre.y()) << "\" r=\""
        << c.radius_m * scale << "\" fill=\"#a8a8a8\" stroke=\"#555\" stroke-width=\"0.8\"/>\n";
  }
  for (const Wall& w : world.walls) {
    if (w.level != level) continue;
    // Solid pieces between doors.
    std::vector<std::pair<double, double>> pieces;
    double cursor = 0;
    std::vector<Door> doors = w.doors;
    std::sort(doors.begin(), doors.end(),
              [](const Door& a, const Door& b) { return a.offset_m < b.offset_m; });
    for (const Door& d : doors) {
      pieces.emplace_back(cursor, d.offset_m);
      cursor = d.offset_m + d.width_m;
    }
    pieces.emplace_back(cursor, w.length());
    for (const auto& [a, b] : pieces) {
      if (b - a < 1e-6) continue;
      const Eigen::Vector2d p = w.start + w.direction() * a, q = w.start + w.direction() * b;
      out << "<line x1=\"" << X(p.x()) << "\" y1=\"" << Y(p.y()) << "\" x2=\"" << X(q.x())
          << "\" y2=\"" << Y(q.y()) << "\" stroke=\"#222\" stroke-width=\""
          << std::max(1.5, w.thickness_m * scale) << "\" stroke-linecap=\"square\"/>\n";
    }
  }
  static const char* kColours[] = {"#d62728", "#1f77b4", "#2ca02c", "#9467bd", "#ff7f0e",
                                   "#17becf", "#e377c2", "#8c564b", "#bcbd22", "#7f7f7f"};
  if (mission != nullptr) {
    for (const Person& p : mission->people) {  // people: thin grey dashed paths
      out << "<polyline fill=\"none\" stroke=\"#777\" stroke-width=\"0.8\" "
             "stroke-dasharray=\"3,3\" points=\"";
      for (const PersonKnot& k : p.knots)
        out << X(k.position.x()) << "," << Y(k.position.y()) << " ";
      out << "\"/>\n";
    }
    for (const RobotPlan& r : mission->robots) {
      const char* colour = kColours[(r.id - 1) % 10];
      out << "<polyline fill=\"none\" stroke=\"" << colour
          << "\" stroke-width=\"1.6\" stroke-opacity=\"0.8\" points=\"";
      const auto& s = r.trajectory.samples();
      for (std::size_t i = 0; i < s.size(); i += 20) out << X(s[i].x) << "," << Y(s[i].y) << " ";
      out << "\"/>\n<circle cx=\"" << X(r.start.x) << "\" cy=\"" << Y(r.start.y)
          << "\" r=\"5\" fill=\"" << colour << "\"/>\n<line x1=\"" << X(r.start.x) << "\" y1=\""
          << Y(r.start.y) << "\" x2=\"" << X(r.start.x + 0.9 * std::cos(r.start.yaw)) << "\" y2=\""
          << Y(r.start.y + 0.9 * std::sin(r.start.yaw)) << "\" stroke=\"" << colour
          << "\" stroke-width=\"2\"/>\n";
    }
  }
  out << "<text x=\"8\" y=\"" << height + 20 << "\" font-size=\"13\" fill=\"#333\">" << world.name;
  if (mission != nullptr) {
    out << " - " << mission->robots.size() << " robots, " << mission->config.duration_s
        << " s, seed " << mission->config.seed << " (dots: unknown start poses)";
  }
  out << "  |  grid: 1 m = " << scale << " px</text>\n</svg>\n";
  return static_cast<bool>(out);
}

}  // namespace msgraphs::sim
