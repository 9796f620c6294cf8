// SPDX-License-Identifier: MIT
// LocalMapper::Relocalise: where a restarted node's robot is, in the map it journaled, when its
// new odometry integration (begun again at identity) cannot say. Two searches, the cheap one
// first: along where the robot was heading when the node stopped, then, if nothing there
// aligns, anywhere it could have walked to in the time (it may have turned a corner, or
// walked back).
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>

#include "msgraphs/core/geometry/se3.hpp"
#include "msgraphs/core/slam/local_mapper.hpp"

namespace msgraphs::core {
namespace {

// Two poses farther apart than a seed's neighbourhood: different places, not one answer.
bool Apart(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b, double apart_m, double apart_rad) {
  const Eigen::Isometry3d d = a.inverse() * b;
  return d.translation().head<2>().norm() > apart_m || Eigen::AngleAxisd(d.linear()).angle() > apart_rad;
}

// The few best-scored seeds, sorted best first and apart: a seed next to a better one would
// only converge to the same answer (insertion into a handful, no allocation).
class SeedRanking {
 public:
  struct Ranked {
    Eigen::Isometry3d seed = Eigen::Isometry3d::Identity();
    double score = 0;
  };

  SeedRanking(std::size_t keep, double apart_m, double apart_rad)
      : keep_(std::min(ranked_.size(), std::max<std::size_t>(1, keep))),
        apart_m_(apart_m),
        apart_rad_(apart_rad) {}

  void Offer(const Eigen::Isometry3d& seed, double score) {
    for (std::size_t j = 0; j < count_; ++j) {
      if (Apart(ranked_[j].seed, seed, apart_m_, apart_rad_)) continue;
      if (ranked_[j].score >= score) return;  // a better neighbour holds the place
      for (std::size_t m = j + 1; m < count_; ++m) ranked_[m - 1] = ranked_[m];
      --count_;
      --j;
    }
    std::size_t at = count_ < keep_ ? count_++ : keep_;
    while (at > 0 && ranked_[at - 1].score < score) {
      if (at < keep_) ranked_[at] = ranked_[at - 1];
      --at;
    }
    if (at < keep_) ranked_[at] = {seed, score};
  }

  std::size_t size() const { return count_; }
  const Eigen::Isometry3d& seed(std::size_t k) const { return ranked_[k].seed; }

 private:
  std::array<Ranked, 8> ranked_;
  std::size_t count_ = 0;
  std::size_t keep_;
  double apart_m_, apart_rad_;
};

}  // namespace

bool LocalMapper::BuildMapNear(const Eigen::Vector2d& a_map, const Eigen::Vector2d& b_map,
                               double radius_m) {
  // Every keyframe near the segment a-b, nearest first, as many as the local map holds.
  const Eigen::Vector2d ab = b_map - a_map;
  std::size_t count = 0;
  for (std::uint32_t k = 0; k < graph_.keyframe_slots() && count < nearby_.size(); ++k) {
    if (!graph_.keyframe_active(k)) continue;
    const Eigen::Vector2d p = graph_.keyframe_pose(k).translation().head<2>();
    const double t =
        ab.squaredNorm() > 0 ? std::clamp((p - a_map).dot(ab) / ab.squaredNorm(), 0.0, 1.0) : 0.0;
    const double distance_m = (p - (a_map + t * ab)).norm();
    if (distance_m <= radius_m) nearby_[count++] = {distance_m, k};
  }
  std::sort(nearby_.begin(), nearby_.begin() + static_cast<std::ptrdiff_t>(count),
            [](const auto& x, const auto& y) { return x.first < y.first; });
  for (std::size_t i = 0; i < count; ++i) recent_scratch_[i] = nearby_[i].second;
  return count > 0 &&
         BuildMapFrom(last_keyframe_, std::span<const std::uint32_t>(recent_scratch_.data(), count));
}

double LocalMapper::SeedScore(const Eigen::Isometry3d& T_last_seed) const {
  // How close a sample of the scan (some 400 points) falls to the local map's voxel means.
  const std::size_t stride = std::max<std::size_t>(1, down_.size() / 400);
  constexpr double kInvTwoSigma2 = 1.0 / (2.0 * 0.15 * 0.15);
  double score = 0;
  for (std::size_t k = 0; k < down_.size(); k += stride) {
    const Eigen::Vector3d q = T_last_seed * down_[k].cast<double>();
    if (const GaussianVoxel* v = local_map_.Lookup(q))
      score += std::exp(-(q - v->mean).squaredNorm() * kInvTwoSigma2);
  }
  return score;
}

double LocalMapper::SeenThroughFraction(const Eigen::Isometry3d& T_last_candidate) const {
  // Negative evidence: a return where the map's keyframes saw through. Only returns higher than
  // the sensor (and below the grid's obstacle band's top) count, and only in cells that rays
  // descending from the sensor crossed: a thing standing on the floor and reaching above the
  // sensor would have stopped such a ray, whereas one lower than the sensor (a box, a table)
  // may lie under rays that passed over it (in a construction site's boxes every right answer
  // had up to 9 % of its band returns "seen through" when every free cell counted). The cell's
  // neighbours must be crossed too and never hit: they absorb a cell of misalignment and walls
  // that grazing rays crossed.
  const Eigen::Isometry3d T_map = graph_.keyframe_pose(last_keyframe_) * T_last_candidate;
  // Heights above the floor under the candidate, in the map (the base may be tilted: at 3
  // degrees a return 8 m away is 0.4 m higher or lower than the base frame says).
  const double floor_z = T_map.translation().z() - config_.base_height_m;
  const double low_m = (T_map * config_.T_base_lidar).translation().z() - floor_z + 0.1;
  const auto high_m = static_cast<double>(config_.grid.obstacle_max_height_m);
  const std::size_t stride = std::max<std::size_t>(1, down_.size() / 2000);
  std::size_t band = 0, seen_through = 0;
  for (std::size_t k = 0; k < down_.size(); k += stride) {
    const Eigen::Vector3d q = T_map * down_[k].cast<double>();
    const double height_m = q.z() - floor_z;
    if (height_m < low_m || height_m > high_m) continue;
    ++band;
    int x = 0, y = 0;
    if (!grid_.ToCell(q.head<2>(), x, y)) continue;
    bool through = true;
    for (int dy = -1; dy <= 1 && through; ++dy) {
      for (int dx = -1; dx <= 1 && through; ++dx) {
        through = grid_.state(x + dx, y + dy) == FreeSpaceGrid::Cell::kFree &&
                  !grid_.ever_occupied(x + dx, y + dy) &&
                  grid_.clear_below_sensor(x + dx, y + dy, 2);
      }
    }
    if (through) ++seen_through;
  }
  return band > 0 ? static_cast<double>(seen_through) / static_cast<double>(band) : 0.0;
}

Expected<Relocalisation> LocalMapper::Relocalise(const LidarScanView& scan,
                                                 const Eigen::Isometry3d& T_new_start,
                                                 const Eigen::Isometry3d& T_new_end,
                                                 const RelocaliseSearch& search) {
  if (!have_keyframe_) return Error{Errc::kNotFound, "relocalise: the map has no keyframe yet"};
  if (scan.points_lidar.size() != scan.time_offset_s.size() || !std::isfinite(scan.start_s) ||
      !std::isfinite(scan.end_s) || scan.end_s < scan.start_s || !(search.step_m > 0) ||
      !(search.lateral_m >= 0) || !(search.yaw_rad >= 0) || !(search.yaw_step_rad >= 0) ||
      !(search.reach_m >= 0) || !std::isfinite(search.reach_m) ||
      !(search.max_seen_through >= 0) ||
      !search.T_odom_from.matrix().allFinite() || !search.T_odom_to.matrix().allFinite()) {
    return Error{Errc::kInvalidArgument, "relocalise: bad scan or search"};
  }
  prepared_ = false;
  if (!Preprocess(scan, T_new_start, T_new_end, false))
    return Error{Errc::kDegenerate, "relocalise: too few usable points"};
  // Seeds relative to the last keyframe (the odometry frame agrees with the map locally), laid
  // out in the gravity-aligned map: at the height where the node stopped (a legged robot walks
  // on the floor; a prediction that extrapolated a rocking base's last step tilts the segment
  // out of it) and level, at headings relative to the last keyframe's. Spot's trot rocks the
  // base by degrees: seeds off the floor, or level with the last keyframe's rocked base (its
  // tilt added to the new one's), miss (LocalMapper/Relocalisation with a rocking base).
  const Eigen::Isometry3d from = last_odometry_.inverse() * search.T_odom_from;
  const Eigen::Isometry3d to = last_odometry_.inverse() * search.T_odom_to;
  const Eigen::Isometry3d& T_map_last = graph_.keyframe_pose(last_keyframe_);
  const Eigen::Isometry3d T_last_map = T_map_last.inverse();
  const double yaw_map_last = std::atan2(T_map_last.linear()(1, 0), T_map_last.linear()(0, 0));
  const Eigen::Vector3d from_map = T_map_last * from.translation();
  Eigen::Vector3d span = T_map_last * to.translation() - from_map;
  span.z() = 0;
  const double yaw_from = std::atan2(from.linear()(1, 0), from.linear()(0, 0));
  double yaw_span = std::atan2(to.linear()(1, 0), to.linear()(0, 0)) - yaw_from;
  yaw_span = std::atan2(std::sin(yaw_span), std::cos(yaw_span));
  // T_last_seed for a level base at p_map (map frame), heading yaw_rad from the last keyframe's.
  const auto seed_at = [&](const Eigen::Vector3d& p_map, double yaw_rad) {
    Eigen::Isometry3d T_map_seed = Eigen::Isometry3d::Identity();
    T_map_seed.linear() = RotZ(yaw_map_last + yaw_rad);
    T_map_seed.translation() = p_map;
    return T_last_map * T_map_seed;
  };
  const int turns = search.yaw_step_rad > 0
                        ? static_cast<int>(std::floor(search.yaw_rad / search.yaw_step_rad + 1e-9))
                        : 0;
  Relocalisation best;
  const double apart_m = 2 * search.step_m + 1e-6, apart_rad = 2 * search.yaw_step_rad + 1e-6;
  // The best few seeds registered by VGICP; the lowest fitness within the scan-matching
  // thresholds wins, and only if no other place passes too: fitness does not tell a
  // corridor's look-alike stretches apart (a scan into space the map saw from afar fits worse
  // than one laid back onto the mapped corridor), so two places that both align are an
  // ambiguity, not an answer (the caller then resumes on the motion the robot had). The
  // segment spans metres of corridor too: under load a node kept down 6 s took the stop point
  // over the robot's place 6 m on.
  bool ambiguous = false;
  const auto register_best = [&](const SeedRanking& ranking) {
    bool found = false;
    double best_fitness = config_.scan_match_max_fitness_m2;
    const double min_overlap = config_.scan_match_min_overlap * static_cast<double>(down_.size());
    // Every place that aligned and was not contradicted.
    std::array<Eigen::Isometry3d, 8> passed;
    std::size_t passed_count = 0;
    Eigen::Isometry3d T_last_best = Eigen::Isometry3d::Identity();
    for (std::size_t k = 0; k < ranking.size(); ++k) {
      auto result = vgicp_.Align(down_.span(), covariances_.span(), local_map_,
                                 local_points_.span(), local_tree_, ranking.seed(k),
                                 config_.scan_matching);
      ++best.registrations;
      if (!result || !result->converged ||
          !(result->fitness < config_.scan_match_max_fitness_m2) ||
          static_cast<double>(result->correspondences) < min_overlap) {
        continue;
      }
      // Farther than the robot could have walked is a look-alike place (a rectangular room
      // turned half round), never the robot.
      const Eigen::Vector3d at_map = T_map_last * result->T_target_source.translation();
      if (search.reach_m > 0 &&
          (at_map - from_map).head<2>().norm() > search.reach_m + search.step_m) {
        continue;
      }
      // Negative evidence: fitness alone does not tell a look-alike place (a room turned
      // round, the next room of a row) from the robot's, as its walls align too; but there
      // the scan's walls stand where the map saw through (a doorway, a room beyond).
      const double seen_through = SeenThroughFraction(result->T_target_source);
      if (seen_through > search.max_seen_through) {
        ++best.contradicted;
        continue;
      }
      if (passed_count < passed.size()) passed[passed_count++] = result->T_target_source;
      if (!(result->fitness < best_fitness)) continue;
      best_fitness = result->fitness;
      best.fitness_m2 = result->fitness;
      best.seen_through = seen_through;
      T_last_best = result->T_target_source;
      best.T_odom_base = last_odometry_ * T_last_best;
      found = true;
    }
    if (found) {
      for (std::size_t k = 0; k < passed_count; ++k) {
        if (Apart(T_last_best, passed[k], apart_m, apart_rad)) {
          ambiguous = true;
          return false;
        }
      }
    }
    return found;
  };

  // 1. Along the segment, one step beyond each end, lateral_m to either side, headings
  //    interpolated along it.
  const bool have_map = BuildMapNear(from_map.head<2>(), (from_map + span).head<2>(),
                                     search.map_radius_m);
  if (have_map) {
    SeedRanking ranking(search.registrations, apart_m, apart_rad);
    const int steps = static_cast<int>(std::ceil(span.head<2>().norm() / search.step_m));
    const int sides = static_cast<int>(std::floor(search.lateral_m / search.step_m + 1e-9));
    for (int i = -1; i <= steps + 1; ++i) {
      const double f = steps == 0 ? 0.0 : static_cast<double>(i) / steps;
      const double yaw = yaw_from + f * yaw_span;
      const Eigen::Matrix3d R_heading = RotZ(yaw_map_last + yaw);
      Eigen::Vector3d on_segment = from_map + f * span;
      if (steps == 0)
        on_segment += R_heading * Eigen::Vector3d(i * search.step_m, 0, 0);  // no span: ahead
      for (int side = -sides; side <= sides; ++side) {
        for (int turn = -turns; turn <= turns && best.candidates < search.max_candidates;
             ++turn) {
          ++best.candidates;
          const Eigen::Isometry3d seed =
              seed_at(on_segment + R_heading * Eigen::Vector3d(0, side * search.step_m, 0),
                      yaw + turn * search.yaw_step_rad);
          ranking.Offer(seed, SeedScore(seed));
        }
      }
    }
    if (register_best(ranking)) return best;
    // Two places on the segment both align: a wider search could only pick one of them by
    // how its seeds happened to rank.
    if (ambiguous)
      return Error{Errc::kNotConverged, "relocalise: places on the segment align alike (ambiguous)"};
  }
  if (search.reach_m <= 0) {
    if (!have_map) return Error{Errc::kDegenerate, "relocalise: no map near the search"};
    return Error{Errc::kNotConverged, "relocalise: no seed aligned to the local map"};
  }

  // 2. Anywhere within reach_m of where the node stopped, nearest first (rings of grid cells
  //    outward), every heading of the search: the robot turned off the line, or back.
  if (!BuildMapNear(from_map.head<2>(), from_map.head<2>(), search.reach_m + search.map_radius_m))
    return Error{Errc::kDegenerate, "relocalise: no map within reach"};
  best.wide = true;
  SeedRanking ranking(search.registrations, apart_m, apart_rad);
  const int rings = static_cast<int>(std::ceil(search.reach_m / search.step_m));
  const std::size_t limit = best.candidates + search.max_reach_candidates;
  for (int ring = 0; ring <= rings && best.candidates < limit; ++ring) {
    for (int ix = -ring; ix <= ring; ++ix) {
      for (int iy = -ring; iy <= ring; ++iy) {
        if (std::max(std::abs(ix), std::abs(iy)) != ring) continue;  // the ring's border only
        const Eigen::Vector3d offset(ix * search.step_m, iy * search.step_m, 0);
        if (offset.norm() > search.reach_m + 1e-9) continue;
        for (int turn = -turns; turn <= turns && best.candidates < limit; ++turn) {
          ++best.candidates;
          const Eigen::Isometry3d seed =
              seed_at(from_map + offset, yaw_from + turn * search.yaw_step_rad);
          ranking.Offer(seed, SeedScore(seed));
        }
      }
    }
  }
  if (register_best(ranking)) return best;
  if (ambiguous)
    return Error{Errc::kNotConverged, "relocalise: places within reach align alike (ambiguous)"};
  if (best.contradicted > 0)
    return Error{Errc::kNotConverged,
                 "relocalise: the places within reach that aligned contradict the map (walls where it saw through)"};
  return Error{Errc::kNotConverged, "relocalise: no seed within reach aligned to the map"};
}

}  // namespace msgraphs::core
