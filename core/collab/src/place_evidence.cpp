// SPDX-License-Identifier: MIT
#include "msgraphs/core/collab/place_evidence.hpp"

#include <algorithm>
#include <cmath>

namespace msgraphs::core {
namespace {

constexpr double kLatticeM = 1.0;  // the coarse lattice places are chosen and judged on

std::size_t Distinct(std::vector<std::uint32_t>& cells) {
  std::sort(cells.begin(), cells.end());
  return static_cast<std::size_t>(std::unique(cells.begin(), cells.end()) - cells.begin());
}

// Share of a disc's lattice points (around `centre`, in the summary's frame) the summary knows.
double KnownShare(const FreeSpaceSummary& s, const Eigen::Vector2d& centre, double radius_m) {
  std::size_t known = 0, all = 0;
  for (double y = -radius_m; y <= radius_m; y += kLatticeM) {
    for (double x = -radius_m; x <= radius_m; x += kLatticeM) {
      if (x * x + y * y > radius_m * radius_m) continue;
      ++all;
      known += s.state_at(centre + Eigen::Vector2d(x, y)) != SummaryCell::kUnknown ? 1u : 0u;
    }
  }
  return all > 0 ? static_cast<double>(known) / static_cast<double>(all) : 0.0;
}

}  // namespace

Status PlaceEvidenceConfig::Validate() const {
  if (!(radius_m > 0 && radius_m <= 12.7f) || max_places_per_peer < 1 || max_asked_per_peer < 1 ||
      max_requests_queued < 1 || !(min_separation_m > 0) || !(min_known_share >= 0 && min_known_share <= 1)) {
    return Error{Errc::kInvalidConfig,
                 "place evidence: radius in (0, 12.7] m, positive capacities and separation, share in [0, 1]"};
  }
  return Ok();
}

void PlaceScorer::Init(std::size_t max_points) {
  explained_.reserve(max_points);
  contradicted_.reserve(max_points);
}

PlaceTally PlaceScorer::Score(std::span<const Eigen::Vector3f> points, const Eigen::Vector2d& centre_b,
                              const PlanarTransform& T_a_b, const FreeSpaceSummary& free_a, double clearance_m) {
  explained_.clear();
  contradicted_.clear();
  const double cell = static_cast<double>(free_a.cell_m());
  const Eigen::Vector2d origin = free_a.origin_m();
  for (const Eigen::Vector3f& q : points) {
    const Eigen::Vector2d p_a = T_a_b * (centre_b + q.head<2>().cast<double>());
    const double fx = (p_a.x() - origin.x()) / cell, fy = (p_a.y() - origin.y()) / cell;
    if (!(fx >= 0 && fy >= 0 && fx < free_a.width() && fy < free_a.height())) continue;
    const int x = static_cast<int>(fx), y = static_cast<int>(fy);
    const auto index = static_cast<std::uint32_t>(y * free_a.width() + x);
    bool occupied = false;
    for (int dy = -1; dy <= 1 && !occupied; ++dy)
      for (int dx = -1; dx <= 1 && !occupied; ++dx) occupied = free_a.state(x + dx, y + dy) == SummaryCell::kOccupied;
    if (occupied) {
      if (explained_.size() < explained_.capacity()) explained_.push_back(index);
    } else if (free_a.state(x, y) == SummaryCell::kFree && static_cast<double>(free_a.clearance_m(p_a)) >= clearance_m) {
      if (contradicted_.size() < contradicted_.capacity()) contradicted_.push_back(index);
    }
  }
  return {Distinct(explained_), Distinct(contradicted_)};
}

DuelOutcome Duel(const PlaceTally& first, const PlaceTally& second, double margin_ratio, std::size_t min_cells) {
  const auto net = [](const PlaceTally& t) {
    return static_cast<double>(t.explained) - static_cast<double>(t.contradicted);
  };
  auto beats = [&](const PlaceTally& w, const PlaceTally& l) {
    return static_cast<double>(l.contradicted) >=
               margin_ratio * static_cast<double>(w.contradicted) + static_cast<double>(min_cells) &&
           net(w) >= net(l);
  };
  if (beats(first, second)) return DuelOutcome::kFirstWins;
  if (beats(second, first)) return DuelOutcome::kSecondWins;
  return DuelOutcome::kUndecided;
}

void PlaceChooser::Init(std::size_t max_cells) {
  near_wall_.assign(max_cells, 0);
  // (width + 1) x (height + 1) <= cells + width + height + 1 <= 2 cells + 2.
  sat_.assign(2 * max_cells + 2, 0);
}

std::uint32_t PlaceChooser::ClutterAround(const FreeSpaceSummary& s, const Eigen::Vector2d& p, double half_m) const {
  const double cell = static_cast<double>(s.cell_m());
  const int w = s.width(), h = s.height();
  const auto clamp_x = [&](double v) { return std::clamp(static_cast<int>(std::floor(v)), 0, w); };
  const auto clamp_y = [&](double v) { return std::clamp(static_cast<int>(std::floor(v)), 0, h); };
  const int x0 = clamp_x((p.x() - half_m - s.origin_m().x()) / cell), x1 = clamp_x((p.x() + half_m - s.origin_m().x()) / cell);
  const int y0 = clamp_y((p.y() - half_m - s.origin_m().y()) / cell), y1 = clamp_y((p.y() + half_m - s.origin_m().y()) / cell);
  const auto at = [&](int x, int y) { return sat_[static_cast<std::size_t>(y) * static_cast<std::size_t>(w + 1) + static_cast<std::size_t>(x)]; };
  return at(x1, y1) - at(x0, y1) - at(x1, y0) + at(x0, y0);
}

std::optional<Eigen::Vector2d> PlaceChooser::Choose(const WallIndex& walls_b, const FreeSpaceSummary& free_b,
                                                    const FreeSpaceSummary& free_a, const PlanarTransform& T_first,
                                                    const PlanarTransform& T_second, std::span<const Eigen::Vector2d> asked,
                                                    const PlaceEvidenceConfig& config) {
  const double radius = static_cast<double>(config.radius_m);
  // Clutter: b's occupied cells farther than a cell and a half from its walls' lines (a wall's
  // own cells, and the next ones its face's returns spill into).
  const int w = free_b.width(), h = free_b.height();
  const std::size_t cells = free_b.cells();
  const bool clutter = cells <= near_wall_.size() && (static_cast<std::size_t>(w) + 1) * (static_cast<std::size_t>(h) + 1) <= sat_.size();
  if (clutter) {
    std::fill_n(near_wall_.begin(), cells, std::uint8_t{0});
    const double cell = static_cast<double>(free_b.cell_m());
    for (const AlignWall& wall : walls_b.walls()) {
      const int steps = static_cast<int>(wall.length_m / (0.5 * cell)) + 1;
      for (int i = 0; i <= steps; ++i) {
        const Eigen::Vector2d q = wall.a + (wall.b - wall.a) * (static_cast<double>(i) / steps);
        const int cx = static_cast<int>(std::floor((q.x() - free_b.origin_m().x()) / cell));
        const int cy = static_cast<int>(std::floor((q.y() - free_b.origin_m().y()) / cell));
        for (int dy = -2; dy <= 2; ++dy)
          for (int dx = -2; dx <= 2; ++dx) {
            const int x = cx + dx, y = cy + dy;
            if (x >= 0 && y >= 0 && x < w && y < h)
              near_wall_[static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x)] = 1;
          }
      }
    }
    const std::size_t stride = static_cast<std::size_t>(w) + 1;
    std::fill_n(sat_.begin(), stride, 0u);
    for (int y = 0; y < h; ++y) {
      std::uint32_t row = 0;
      sat_[static_cast<std::size_t>(y + 1) * stride] = 0;
      for (int x = 0; x < w; ++x) {
        const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x);
        row += free_b.state(x, y) == SummaryCell::kOccupied && near_wall_[i] == 0 ? 1u : 0u;
        sat_[static_cast<std::size_t>(y + 1) * stride + static_cast<std::size_t>(x + 1)] =
            sat_[static_cast<std::size_t>(y) * stride + static_cast<std::size_t>(x + 1)] + row;
      }
    }
  }
  std::optional<Eigen::Vector2d> best;
  std::uint32_t best_clutter = 0;
  double best_share = 0;
  for (const AlignWall& wall : walls_b.walls()) {
    const auto samples = static_cast<int>(std::floor(wall.length_m / kLatticeM)) + 1;
    for (int i = 0; i < samples; ++i) {
      const double s = samples > 1 ? static_cast<double>(i) / static_cast<double>(samples - 1) : 0.5;
      const Eigen::Vector2d c = wall.a + s * (wall.b - wall.a);
      if ((T_first * c - T_second * c).norm() < config.min_separation_m) continue;
      bool near_asked = false;
      for (const Eigen::Vector2d& q : asked) near_asked = near_asked || (q - c).norm() < 0.5 * radius;
      if (near_asked) continue;
      const double share = std::min({KnownShare(free_b, c, radius), KnownShare(free_a, T_first * c, radius),
                                     KnownShare(free_a, T_second * c, radius)});
      if (share < config.min_known_share) continue;
      const std::uint32_t around = clutter ? ClutterAround(free_b, c, radius) : 0u;
      if (!best || around > best_clutter || (around == best_clutter && share > best_share)) {
        best = c;
        best_clutter = around;
        best_share = share;
      }
    }
  }
  return best;
}

}  // namespace msgraphs::core
