// SPDX-License-Identifier: MIT
#include "msgraphs/core/perception/plane_extraction.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <numbers>

namespace msgraphs::core {
namespace {

// Small deterministic generator (splitmix64): no allocation, same sequence everywhere.
struct Rng {
  std::uint64_t s;
  std::uint64_t Next() {
    std::uint64_t z = (s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  std::size_t Below(std::size_t n) { return static_cast<std::size_t>(Next() % n); }
};

void TangentBasis(const Eigen::Vector3d& n, Eigen::Vector3d& u, Eigen::Vector3d& v) {
  // u horizontal for walls (along the wall), otherwise any unit vector normal to n.
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  u = z.cross(n);
  if (u.norm() < 1e-6) u = Eigen::Vector3d::UnitX().cross(n);
  u.normalize();
  v = n.cross(u).normalized();
}

}  // namespace

Status PlaneExtractionConfig::Validate() const {
  if (!(distance_threshold_m > 0) || !(normal_threshold_deg > 0) || ransac_iterations < 1 || score_subset < 10 ||
      min_vertical_inliers < 3 || min_horizontal_inliers < 3 || !(max_tilt_deg > 0 && max_tilt_deg < 45) ||
      !(segment_gap_m > 0) || max_planes == 0 || !(min_sigma_m > 0)) {
    return Error{Errc::kInvalidConfig, "planes: thresholds must be positive (tilt below 45 degrees)"};
  }
  return Ok();
}

void PlaneExtractor::Init(std::size_t max_points) {
  remaining_.assign(max_points, 0);
  inliers_.assign(max_points, 0);
  used_.assign(max_points, 0);
  round_ = 0;
  along_.assign(max_points, {0.0f, 0});
  segment_.assign(max_points, 0);
  subset_.assign(max_points, 0);
}

bool PlaneExtractor::FitAndDescribe(std::span<const Eigen::Vector3f> points, std::span<const std::uint32_t> members,
                                    const PlaneExtractionConfig& config, const Eigen::Vector3d& up,
                                    ExtractedPlane& plane) const {
  if (members.size() < 3) return false;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (std::uint32_t i : members) mean += points[i].cast<double>();
  mean /= static_cast<double>(members.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (std::uint32_t i : members) {
    const Eigen::Vector3d q = points[i].cast<double>() - mean;
    scatter += q * q.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  eig.computeDirect(scatter);
  Eigen::Vector3d n = eig.eigenvectors().col(0);
  if (!n.allFinite()) return false;
  double d = -n.dot(mean);
  if (d < 0) {  // towards the sensor (the frame's origin)
    n = -n;
    d = -d;
  }
  Eigen::Vector3d u, v;
  TangentBasis(n, u, v);
  Eigen::Matrix3d information = Eigen::Matrix3d::Zero();
  double sum_r2 = 0;
  double u_min = 1e18, u_max = -1e18, z_min = 1e18, z_max = -1e18;
  for (std::uint32_t i : members) {
    const Eigen::Vector3d p = points[i].cast<double>();
    const double r = n.dot(p) + d;
    sum_r2 += r * r;
    const Eigen::Vector3d J(u.dot(p), v.dot(p), 1.0);
    information += J * J.transpose();
    const double a = u.dot(p);
    u_min = std::min(u_min, a);
    u_max = std::max(u_max, a);
    const double h = up.dot(p);
    z_min = std::min(z_min, h);
    z_max = std::max(z_max, h);
  }
  const double rms = std::sqrt(sum_r2 / static_cast<double>(members.size()));
  const double sigma = std::max(rms, static_cast<double>(config.min_sigma_m));
  // Regularised inverse: a thin strip of points leaves one direction weakly determined, never
  // undetermined, so the covariance stays finite.
  const Eigen::Matrix3d cov = (information + 1e-9 * Eigen::Matrix3d::Identity()).inverse() * sigma * sigma;
  if (!cov.allFinite()) return false;
  plane.normal = n;
  plane.d = d;
  plane.basis_u = u;
  plane.basis_v = v;
  plane.covariance = cov;
  plane.inliers = members.size();
  plane.rms_m = rms;
  plane.centroid = mean;
  plane.u_min = u_min;
  plane.u_max = u_max;
  plane.z_min = z_min;
  plane.z_max = z_max;
  return true;
}

Status PlaneExtractor::Extract(std::span<const Eigen::Vector3f> points, std::span<const Eigen::Vector3f> normals,
                               const PlaneExtractionConfig& config, BoundedVector<ExtractedPlane>& planes,
                               const Eigen::Vector3d& up_given) {
  planes.clear();
  if (Status s = config.Validate(); !s) return s;
  // Gravity's up is within a few degrees of the frame's z on a walking robot; anything else
  // is a broken estimate, and heights along it would mislabel every wall.
  if (!up_given.allFinite() || !(up_given.norm() > 0.5) || !(up_given.normalized().z() > 0.5))
    return Error{Errc::kInvalidArgument, "planes: up must be finite and within 60 degrees of the frame's z"};
  const Eigen::Vector3d up = up_given.normalized();
  if (round_ > 0xFFFF0000u) {  // marks would wrap: forget them explicitly
    std::fill(used_.begin(), used_.end(), 0);
    round_ = 0;
  }
  if (points.size() != normals.size()) return Error{Errc::kInvalidArgument, "planes: one normal per point"};
  if (points.size() > remaining_.size()) return Error{Errc::kCapacityExceeded, "planes: more points than Init allowed"};
  std::size_t remaining = 0;
  for (std::uint32_t i = 0; i < points.size(); ++i) {
    if (points[i].allFinite() && normals[i].allFinite() && normals[i].squaredNorm() > 0.5f) remaining_[remaining++] = i;
  }
  const float cos_normal = std::cos(config.normal_threshold_deg * std::numbers::pi_v<float> / 180.0f);
  const double sin_tilt = std::sin(static_cast<double>(config.max_tilt_deg) * std::numbers::pi / 180.0);
  const std::size_t min_inliers = std::min(config.min_vertical_inliers, config.min_horizontal_inliers);
  Rng rng{config.seed};
  std::size_t attempts = 0;

  while (remaining >= min_inliers && planes.size() < config.max_planes && attempts < 4 * config.max_planes) {
    ++attempts;
    // A fixed random subset for scoring keeps each hypothesis O(subset).
    const std::size_t subset = std::min(config.score_subset, remaining);
    for (std::size_t k = 0; k < subset; ++k) subset_[k] = remaining_[rng.Below(remaining)];
    std::size_t best_score = 0;
    Eigen::Vector3f best_n = Eigen::Vector3f::UnitZ();
    float best_d = 0;
    for (int it = 0; it < config.ransac_iterations; ++it) {
      const std::uint32_t s = remaining_[rng.Below(remaining)];
      const Eigen::Vector3f n = normals[s];
      const float d = -n.dot(points[s]);
      std::size_t score = 0;
      for (std::size_t k = 0; k < subset; ++k) {
        const std::uint32_t i = subset_[k];
        if (std::fabs(n.dot(points[i]) + d) <= config.distance_threshold_m && std::fabs(n.dot(normals[i])) >= cos_normal) ++score;
      }
      if (score > best_score) {
        best_score = score;
        best_n = n;
        best_d = d;
      }
    }
    // Inliers on all remaining points; refit; inliers again with the refined plane.
    auto collect = [&](const Eigen::Vector3f& n, float d) {
      std::size_t count = 0;
      for (std::size_t k = 0; k < remaining; ++k) {
        const std::uint32_t i = remaining_[k];
        if (std::fabs(n.dot(points[i]) + d) <= config.distance_threshold_m && std::fabs(n.dot(normals[i])) >= cos_normal) {
          inliers_[count++] = i;
        }
      }
      return count;
    };
    std::size_t count = collect(best_n, best_d);
    if (count < min_inliers) break;
    ExtractedPlane fit;
    if (!FitAndDescribe(points, {inliers_.data(), count}, config, up, fit)) break;
    count = collect(fit.normal.cast<float>(), static_cast<float>(fit.d));
    if (count < min_inliers) break;

    // Consume the inliers whatever happens next, so the loop always progresses. Points in a
    // wider band around the plane with agreeing normals are consumed too (not fitted): the
    // noise tail of the same surface, which would otherwise come back as a duplicate plane.
    ++round_;
    for (std::size_t k = 0; k < count; ++k) used_[inliers_[k]] = round_;
    {
      const Eigen::Vector3f n = fit.normal.cast<float>();
      const auto d = static_cast<float>(fit.d);
      for (std::size_t k = 0; k < remaining; ++k) {
        const std::uint32_t i = remaining_[k];
        if (std::fabs(n.dot(points[i]) + d) <= 3.0f * config.distance_threshold_m &&
            std::fabs(n.dot(normals[i])) >= cos_normal) {
          used_[i] = round_;
        }
      }
    }
    std::size_t kept = 0;
    for (std::size_t k = 0; k < remaining; ++k) {
      const std::uint32_t i = remaining_[k];
      if (used_[i] != round_) remaining_[kept++] = i;
    }
    remaining = kept;

    const double nz = std::fabs(fit.normal.z());
    const bool vertical = nz <= sin_tilt;
    const bool horizontal = nz >= std::cos(std::asin(sin_tilt));
    if (!vertical && !horizontal) continue;  // slanted: a ramp, a chair back; not a layer element
    if (horizontal) {
      if (count < config.min_horizontal_inliers) continue;
      ExtractedPlane plane;
      if (!FitAndDescribe(points, {inliers_.data(), count}, config, up, plane)) continue;
      plane.kind = PlaneKind::kHorizontal;
      if (!planes.try_push_back(plane)) return Error{Errc::kCapacityExceeded, "planes: output full"};
      continue;
    }
    // Split the wall where its points leave a gap along it.
    Eigen::Vector3d u, v;
    TangentBasis(fit.normal, u, v);
    for (std::size_t k = 0; k < count; ++k) {
      along_[k] = {static_cast<float>(u.dot(points[inliers_[k]].cast<double>())), inliers_[k]};
    }
    std::sort(along_.begin(), along_.begin() + static_cast<std::ptrdiff_t>(count));
    std::size_t start = 0;
    for (std::size_t k = 1; k <= count; ++k) {
      if (k < count && along_[k].first - along_[k - 1].first <= config.segment_gap_m) continue;
      const std::size_t n = k - start;
      if (n >= config.min_vertical_inliers) {
        for (std::size_t j = 0; j < n; ++j) segment_[j] = along_[start + j].second;
        ExtractedPlane plane;
        if (FitAndDescribe(points, {segment_.data(), n}, config, up, plane)) {
          plane.kind = PlaneKind::kVertical;
          if (!planes.try_push_back(plane)) return Error{Errc::kCapacityExceeded, "planes: output full"};
        }
      }
      start = k;
    }
  }
  return Ok();
}

}  // namespace msgraphs::core
