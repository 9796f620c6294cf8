// SPDX-License-Identifier: MIT
#include "msgraphs/core/collab/alignment_search.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <numbers>

namespace msgraphs::core {
namespace {

constexpr double kPi = std::numbers::pi;

double Wrap(double a) { return std::remainder(a, 2 * kPi); }

// Distance along a wall's line from `p` (on the line) to its extent (0 inside it).
double OutsideExtent(const AlignWall& w, const Eigen::Vector2d& p) {
  const Eigen::Vector2d u(-w.n.y(), w.n.x());
  const double s = u.dot(p), s0 = std::min(u.dot(w.a), u.dot(w.b)), s1 = std::max(u.dot(w.a), u.dot(w.b));
  return s < s0 ? s0 - s : s > s1 ? s - s1 : 0.0;
}

// Which side of the other wall's face `w` leaves the corner towards: +1 in front of it, -1
// behind, 0 when it runs through the corner (a T-junction seen from the through wall).
std::int8_t Side(const AlignWall& w, const Eigen::Vector2d& p, const Eigen::Vector2d& other_n, double reach) {
  const Eigen::Vector2d u(-w.n.y(), w.n.x());
  const double s = u.dot(p), s0 = std::min(u.dot(w.a), u.dot(w.b)), s1 = std::max(u.dot(w.a), u.dot(w.b));
  if (s > s0 + reach && s < s1 - reach) return 0;
  const Eigen::Vector2d mid = 0.5 * (w.a + w.b);
  return other_n.dot(mid - p) >= 0 ? 1 : -1;
}

std::uint64_t Pack(std::int64_t a, std::int64_t b, std::int64_t c) {
  const auto f = [](std::int64_t v) { return static_cast<std::uint64_t>(v + (1 << 20)) & 0x1FFFFF; };
  return (f(a) << 42) | (f(b) << 21) | f(c);
}

std::uint64_t Mix(std::uint64_t k) {
  k ^= k >> 33;
  k *= 0xff51afd7ed558ccdULL;
  k ^= k >> 33;
  return k;
}

bool SizesMatch(double a, double b, double tolerance_m) {
  return std::fabs(a - b) <= std::max(tolerance_m, 0.1 * std::max(a, b));
}

}  // namespace

Status AlignmentSearchConfig::Validate() const {
  if (!(min_wall_length_m > 0) || !(corner_reach_m >= 0) || !(min_corner_angle_rad > 0 && min_corner_angle_rad < 1.5) ||
      !(corner_angle_tolerance_rad > 0) || !(room_size_tolerance_m >= 0) || !(bin_m > 0) || !(bin_rad > 0) ||
      !(keep_constraint_m >= 0) || refine_iterations < 0 || !(same_distance_m > 0) || !(same_angle_rad > 0) ||
      max_corners < 4 || max_hypotheses < 2 || max_clusters < 16 || !std::has_single_bit(max_clusters) ||
      !(min_channel_agreement_m >= 0) || max_channel_families < 16 || !std::has_single_bit(max_channel_families)) {
    return Error{Errc::kInvalidConfig,
                 "alignment search: positive tolerances, a power-of-two cluster table, room for corners"};
  }
  return agreement.Validate();
}

Status AlignmentSearch::Init(const AlignmentSearchConfig& config) {
  if (auto s = config.Validate(); !s) return s;
  config_ = config;
  corners_a_.Init(config.max_corners);
  corners_b_.Init(config.max_corners);
  clusters_.assign(config.max_clusters, Cluster{});
  hypotheses_.Init(config.max_hypotheses);
  families_.assign(config.max_channel_families, AlignmentChannelFamily{});
  channels_.Init(config.max_channels);
  return Ok();
}

void AlignmentSearch::Corners(const WallIndex& index, BoundedVector<Corner>& out) {
  out.clear();
  const std::span<const AlignWall> walls = index.walls();
  const double reach = config_.corner_reach_m;
  for (std::size_t i = 0; i < walls.size(); ++i) {
    if (walls[i].length_m < config_.min_wall_length_m) continue;
    for (std::size_t j = i + 1; j < walls.size(); ++j) {
      if (walls[j].length_m < config_.min_wall_length_m) continue;
      const AlignWall* wi = &walls[i];
      const AlignWall* wj = &walls[j];
      double opening = Wrap(wj->angle_rad - wi->angle_rad);
      if (opening < 0) {
        std::swap(wi, wj);
        opening = -opening;
      }
      if (opening < config_.min_corner_angle_rad || opening > kPi - config_.min_corner_angle_rad) continue;
      // Where the two lines meet: n_i.p = -d_i, n_j.p = -d_j.
      Eigen::Matrix2d N;
      N << wi->n.transpose(), wj->n.transpose();
      const Eigen::Vector2d p = N.inverse() * Eigen::Vector2d(-wi->d, -wj->d);
      if (!p.allFinite() || OutsideExtent(*wi, p) > reach || OutsideExtent(*wj, p) > reach) continue;
      Corner c;
      c.p = p;
      c.angle_rad = wi->angle_rad;
      c.opening_rad = opening;
      c.side_i = Side(*wi, p, wj->n, reach);
      c.side_j = Side(*wj, p, wi->n, reach);
      c.wall_i = static_cast<std::uint32_t>(wi - walls.data());
      c.wall_j = static_cast<std::uint32_t>(wj - walls.data());
      if (!out.try_push_back(c)) {
        ++stats_.corners_dropped;
        return;
      }
    }
  }
}

void AlignmentSearch::Vote(const PlanarTransform& T, std::uint32_t votes, std::uint8_t source) {
  ++stats_.candidates;
  const std::uint64_t key = Pack(std::llround(Wrap(T.yaw_rad) / config_.bin_rad),
                                 std::llround(T.t_m.x() / config_.bin_m), std::llround(T.t_m.y() / config_.bin_m));
  const std::size_t mask = clusters_.size() - 1;
  for (std::size_t probe = 0, k = Mix(key) & mask; probe < clusters_.size(); ++probe, k = (k + 1) & mask) {
    Cluster& c = clusters_[k];
    if (c.used && c.key != key) continue;
    if (!c.used) {
      // Keep the table at most three quarters full: probes stay short.
      if (4 * (stats_.clusters + 1) > 3 * clusters_.size()) {
        ++stats_.clusters_dropped;
        return;
      }
      c = Cluster{};
      c.used = true;
      c.key = key;
      ++stats_.clusters;
    }
    c.votes += votes;
    c.sources |= source;
    c.cos_sum += votes * std::cos(T.yaw_rad);
    c.sin_sum += votes * std::sin(T.yaw_rad);
    c.t_sum += votes * T.t_m;
    return;
  }
}

void AlignmentSearch::Keep(const Hypothesis& h) {
  for (Hypothesis& k : hypotheses_) {
    if (!SameTransform(k.T_a_b, h.T_a_b, config_.same_distance_m, config_.same_angle_rad)) continue;
    const std::uint32_t votes = k.votes + h.votes;
    const std::uint8_t sources = k.sources | h.sources;
    if (h.agreement.agreement_m > k.agreement.agreement_m) k = h;
    k.votes = votes;
    k.sources = sources;
    return;
  }
  if (hypotheses_.try_push_back(h)) return;
  ++stats_.hypotheses_dropped;
  // Full: the weakest gives way.
  Hypothesis* worst = &hypotheses_[0];
  for (Hypothesis& k : hypotheses_) {
    if (k.agreement.agreement_m < worst->agreement.agreement_m) worst = &k;
  }
  if (worst->agreement.agreement_m < h.agreement.agreement_m) *worst = h;
}

void AlignmentSearch::Channels(const WallIndex& a, const WallIndex& b) {
  if (!(config_.min_channel_agreement_m > 0) || channels_.capacity() == 0) return;
  const std::size_t mask = families_.size() - 1;
  for (const AlignWall& wa : a.walls()) {
    if (wa.length_m < config_.min_wall_length_m) continue;
    // The line's direction taken once (a corridor's two faces are one family): the normal's
    // angle in [0, pi), the offset across measured along it.
    const bool flip = wa.angle_rad < 0;
    const Eigen::Vector2d n = flip ? Eigen::Vector2d(-wa.n) : wa.n;
    const Eigen::Vector2d u(-n.y(), n.x());
    const double axis_rad = flip ? wa.angle_rad + kPi : wa.angle_rad;
    for (const AlignWall& wb : b.walls()) {
      if (wb.length_m < config_.min_wall_length_m) continue;
      const double yaw = Wrap(wa.angle_rad - wb.angle_rad);
      // b's wall on a's line: wa.n . t = wb.d - wa.d (both lines n.p + d = 0).
      const double across = (flip ? -1.0 : 1.0) * (wb.d - wa.d);
      const Eigen::Matrix2d R = PlanarTransform{yaw, Eigen::Vector2d::Zero()}.R();
      const double along = u.dot(0.5 * (wa.a + wa.b) - R * (0.5 * (wb.a + wb.b)));
      const double weight = std::min(wa.length_m, wb.length_m);
      const std::uint64_t key = Pack(std::llround(yaw / config_.bin_rad), std::llround(axis_rad / config_.bin_rad),
                                     std::llround(across / config_.bin_m));
      bool placed = false;
      for (std::size_t probe = 0, k = Mix(key) & mask; probe < families_.size(); ++probe, k = (k + 1) & mask) {
        AlignmentChannelFamily& f = families_[k];
        if (f.used && f.key != key) continue;
        if (!f.used) {
          if (4 * (stats_.channel_families + 1) > 3 * families_.size()) break;
          f = AlignmentChannelFamily{};
          f.used = true;
          f.key = key;
          f.n = n;
          ++stats_.channel_families;
        }
        f.weight_m += weight;
        f.cos_sum += weight * std::cos(yaw);
        f.sin_sum += weight * std::sin(yaw);
        f.across_sum += weight * across;
        f.along_sum += weight * along;
        placed = true;
        break;
      }
      if (!placed) ++stats_.channel_families_dropped;
    }
  }
  for (const AlignmentChannelFamily& f : families_) {
    if (!f.used || f.weight_m < config_.min_channel_agreement_m) continue;
    const Eigen::Vector2d u(-f.n.y(), f.n.x());
    const PlanarTransform T{std::atan2(f.sin_sum, f.cos_sum), (f.across_sum * f.n + f.along_sum * u) / f.weight_m};
    ++stats_.channels_scored;
    Hypothesis h = Evaluate(a, b, T);
    if (h.agreement.agreement_m < config_.min_channel_agreement_m) continue;
    h.votes = 1;
    h.sources = kFromChannel;
    bool same = false;
    for (Hypothesis& k : channels_) {
      if (!SameTransform(k.T_a_b, h.T_a_b, config_.same_distance_m, config_.same_angle_rad)) continue;
      if (h.agreement.agreement_m > k.agreement.agreement_m) k = h;
      same = true;
      break;
    }
    if (same || channels_.try_push_back(h)) continue;
    Hypothesis* worst = &channels_[0];
    for (Hypothesis& k : channels_) {
      if (k.agreement.agreement_m < worst->agreement.agreement_m) worst = &k;
    }
    if (worst->agreement.agreement_m < h.agreement.agreement_m) *worst = h;
  }
  std::sort(channels_.begin(), channels_.end(), [](const Hypothesis& x, const Hypothesis& y) {
    return x.agreement.agreement_m > y.agreement.agreement_m;
  });
}

Hypothesis AlignmentSearch::Evaluate(const WallIndex& a, const WallIndex& b, const PlanarTransform& T) const {
  Hypothesis h;
  h.T_a_b = RefineTransform(a, b, T, config_.agreement, config_.refine_iterations);
  h.agreement = ScoreAgreement(a, b, h.T_a_b, config_.agreement);
  return h;
}

std::size_t AlignmentSearch::Search(const WallIndex& a, std::span<const DistilledRoom> rooms_a, const WallIndex& b,
                                    std::span<const DistilledRoom> rooms_b, std::span<const PlanarTransform> seeds,
                                    bool self) {
  stats_ = {};
  hypotheses_.clear();
  channels_.clear();
  for (Cluster& c : clusters_) c.used = false;
  for (AlignmentChannelFamily& f : families_) f.used = false;
  Corners(a, corners_a_);
  if (self) {
    corners_b_.clear();
    for (const Corner& c : corners_a_) static_cast<void>(corners_b_.try_push_back(c));
  } else {
    Corners(b, corners_b_);
  }
  stats_.corners_a = corners_a_.size();
  stats_.corners_b = corners_b_.size();
  for (std::size_t i = 0; i < corners_a_.size(); ++i) {
    const Corner& ca = corners_a_[i];
    for (std::size_t j = 0; j < corners_b_.size(); ++j) {
      if (self && i == j) continue;
      const Corner& cb = corners_b_[j];
      if (std::fabs(ca.opening_rad - cb.opening_rad) > config_.corner_angle_tolerance_rad) continue;
      if (ca.side_i != 0 && cb.side_i != 0 && ca.side_i != cb.side_i) continue;
      if (ca.side_j != 0 && cb.side_j != 0 && ca.side_j != cb.side_j) continue;
      // Yaw from both walls' normals (their mean on the circle), then the meeting points.
      const double y1 = Wrap(ca.angle_rad - cb.angle_rad);
      const double y2 = Wrap(y1 + (ca.opening_rad - cb.opening_rad) * 0.5);
      PlanarTransform T{y2, Eigen::Vector2d::Zero()};
      T.t_m = ca.p - T.R() * cb.p;
      Vote(T, 1, kFromCorners);
    }
  }
  // Rooms of the same size, in every orientation their rectangle allows.
  for (const DistilledRoom& ra : rooms_a) {
    if (ra.shape != RoomShape::kFourWall) continue;
    for (const DistilledRoom& rb : rooms_b) {
      if (rb.shape != RoomShape::kFourWall || (self && &ra == &rb)) continue;
      const double tol = config_.room_size_tolerance_m;
      const bool same = SizesMatch(ra.size_x_m, rb.size_x_m, tol) && SizesMatch(ra.size_y_m, rb.size_y_m, tol);
      const bool swapped = SizesMatch(ra.size_x_m, rb.size_y_m, tol) && SizesMatch(ra.size_y_m, rb.size_x_m, tol);
      for (int turn = 0; turn < 4; ++turn) {
        if ((turn % 2 == 0 && !same) || (turn % 2 == 1 && !swapped)) continue;
        PlanarTransform T{Wrap(ra.yaw_rad - rb.yaw_rad + turn * 0.5 * kPi), Eigen::Vector2d::Zero()};
        T.t_m = ra.centre - T.R() * rb.centre;
        // A room pair is worth its four corners.
        Vote(T, 4, kFromRooms);
      }
    }
  }
  for (const PlanarTransform& s : seeds) Vote(s, 4, kFromSeed);

  for (const Cluster& c : clusters_) {
    if (!c.used) continue;
    PlanarTransform T{std::atan2(c.sin_sum, c.cos_sum), c.t_sum / static_cast<double>(c.votes)};
    if (self && std::fabs(Wrap(T.yaw_rad)) < config_.same_angle_rad && T.t_m.norm() < config_.same_distance_m)
      continue;  // the map onto itself: not a symmetry
    const WallAgreement quick = ScoreAgreement(a, b, T, config_.agreement);
    if (quick.constraint_m < config_.keep_constraint_m) continue;
    ++stats_.kept;
    Hypothesis h = Evaluate(a, b, T);
    if (h.agreement.constraint_m < config_.keep_constraint_m) continue;
    if (self && std::fabs(Wrap(h.T_a_b.yaw_rad)) < config_.same_angle_rad &&
        h.T_a_b.t_m.norm() < config_.same_distance_m) {
      continue;
    }
    h.votes = c.votes;
    h.sources = c.sources;
    Keep(h);
  }
  std::sort(hypotheses_.begin(), hypotheses_.end(), [](const Hypothesis& x, const Hypothesis& y) {
    return x.agreement.agreement_m > y.agreement.agreement_m;
  });
  if (!self) Channels(a, b);
  return hypotheses_.size();
}

}  // namespace msgraphs::core
