// SPDX-License-Identifier: MIT
#include "walls.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace msgraphs::sim::building {
namespace {

// Edges closer than these lie on one line: outlines come from the same vertex arithmetic, so
// shared edges agree to ~1e-12; these only absorb rounding, never join distinct walls (the
// generator's walls are centimetres apart at least).
constexpr double kAngleTolerance = 1e-7;
constexpr double kOffsetTolerance_m = 1e-5;
constexpr double kPointTolerance_m = 1e-6;

struct Edge {
  int room;
  Vec2 p, q;          // on the line, p before q along the line's direction
  bool room_on_left;  // the room lies on the left of p -> q
  double angle;       // direction modulo pi
  double rho = 0, t0 = 0, t1 = 0;
};

}  // namespace

bool BuildWalls(const Plan& plan, std::vector<PlanWall>& walls, std::string& error) {
  std::vector<Edge> edges;
  for (std::size_t r = 0; r < plan.rooms.size(); ++r) {
    const Polygon& poly = plan.rooms[r].polygon;
    for (std::size_t i = 0; i < poly.size(); ++i) {
      const Vec2& p = poly[i];
      const Vec2& q = poly[(i + 1) % poly.size()];
      if ((q - p).norm() < kPointTolerance_m) continue;
      double angle = std::atan2(q.y() - p.y(), q.x() - p.x());
      if (angle < 0) angle += std::numbers::pi;
      if (angle >= std::numbers::pi) angle -= std::numbers::pi;
      // Outlines are counter-clockwise: the room is on the left of each edge.
      edges.push_back({static_cast<int>(r), p, q, true, angle});
    }
  }
  std::vector<std::size_t> order(edges.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return edges[a].angle < edges[b].angle || (edges[a].angle == edges[b].angle && a < b);
  });
  // Direction clusters; the first and last join when they straddle 0 = pi.
  std::vector<std::vector<std::size_t>> directions;
  for (std::size_t k = 0; k < order.size(); ++k) {
    if (k == 0 || edges[order[k]].angle - edges[order[k - 1]].angle > kAngleTolerance) {
      directions.emplace_back();
    }
    directions.back().push_back(order[k]);
  }
  if (directions.size() > 1 && edges[directions.front().front()].angle < kAngleTolerance &&
      edges[directions.back().back()].angle > std::numbers::pi - kAngleTolerance) {
    directions.front().insert(directions.front().end(), directions.back().begin(),
                              directions.back().end());
    directions.pop_back();
  }

  int exterior_count = 0, interior_count = 0;
  for (auto& cluster : directions) {
    const Vec2 d = (edges[cluster.front()].q - edges[cluster.front()].p).normalized();
    const Vec2 n(-d.y(), d.x());
    for (std::size_t e : cluster) {
      Edge& edge = edges[e];
      if ((edge.q - edge.p).dot(d) < 0) {
        std::swap(edge.p, edge.q);
        edge.room_on_left = !edge.room_on_left;
      }
      edge.rho = n.dot(edge.p);
      edge.t0 = d.dot(edge.p);
      edge.t1 = d.dot(edge.q);
    }
    std::sort(cluster.begin(), cluster.end(), [&](std::size_t a, std::size_t b) {
      return edges[a].rho < edges[b].rho || (edges[a].rho == edges[b].rho && a < b);
    });
    for (std::size_t first = 0; first < cluster.size();) {
      std::size_t last = first + 1;
      while (last < cluster.size() &&
             edges[cluster[last]].rho - edges[cluster[last - 1]].rho < kOffsetTolerance_m)
        ++last;
      // One line: cut it at every edge end into elementary pieces.
      std::vector<std::pair<double, Vec2>> cuts;
      for (std::size_t k = first; k < last; ++k) {
        const Edge& edge = edges[cluster[k]];
        cuts.emplace_back(edge.t0, edge.p);
        cuts.emplace_back(edge.t1, edge.q);
      }
      std::sort(cuts.begin(), cuts.end(),
                [](const auto& a, const auto& b) { return a.first < b.first; });
      std::vector<std::pair<double, Vec2>> points;
      for (const auto& c : cuts) {
        if (points.empty() || c.first - points.back().first > kPointTolerance_m)
          points.push_back(c);
      }
      const std::size_t pieces = points.size() - 1;
      std::vector<int> left(pieces, -1), right(pieces, -1);
      for (std::size_t k = first; k < last; ++k) {
        const Edge& edge = edges[cluster[k]];
        for (std::size_t i = 0; i < pieces; ++i) {
          const double mid = 0.5 * (points[i].first + points[i + 1].first);
          if (mid <= edge.t0 || mid >= edge.t1) continue;
          int& side = edge.room_on_left ? left[i] : right[i];
          if (side >= 0) {
            error =
                "rooms " + std::to_string(side) + " and " + std::to_string(edge.room) + " overlap";
            return false;
          }
          side = edge.room;
        }
      }
      // Runs of pieces of one kind make walls.
      for (std::size_t i = 0; i < pieces;) {
        if (left[i] < 0 && right[i] < 0) {
          ++i;
          continue;
        }
        if (left[i] == right[i]) {
          error = "room " + std::to_string(left[i]) + " lies on both sides of an edge";
          return false;
        }
        const bool exterior = left[i] < 0 || right[i] < 0;
        std::size_t j = i;
        while (j < pieces && (left[j] >= 0 || right[j] >= 0) &&
               ((left[j] < 0 || right[j] < 0) == exterior))
          ++j;
        PlanWall w;
        w.exterior = exterior;
        w.wall.id = exterior ? "e" + std::to_string(++exterior_count)
                             : "i" + std::to_string(++interior_count);
        w.wall.start = points[i].second;
        w.wall.end = points[j].second;
        w.wall.thickness_m =
            exterior ? plan.walls.exterior_thickness_m : plan.walls.interior_thickness_m;
        w.wall.material = exterior ? plan.walls.exterior_material : plan.walls.interior_material;
        w.wall.height_m = plan.ceiling_m;
        for (std::size_t k = i; k < j; ++k) {
          const double s0 = points[k].first - points[i].first,
                       s1 = points[k + 1].first - points[i].first;
          if (!w.spans.empty() && w.spans.back().left == left[k] &&
              w.spans.back().right == right[k]) {
            w.spans.back().s1_m = s1;
          } else {
            w.spans.push_back({s0, s1, left[k], right[k]});
          }
        }
        walls.push_back(std::move(w));
        i = j;
      }
      first = last;
    }
  }
  return true;
}

}  // namespace msgraphs::sim::building
