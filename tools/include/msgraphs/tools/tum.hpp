// SPDX-License-Identifier: MIT
// TUM trajectories for the host tools and tests: read, write, look up by stamp, and the
// absolute trajectory error (poses associated by stamp, the estimate aligned to the truth by a
// rigid SE(3) Umeyama fit, then RMSE / mean / median / max, as evo's `evo_ape tum --align`).
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "msgraphs/core/geometry/umeyama.hpp"

namespace msgraphs::tools {

struct StampedPose {
  double t = 0;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
};

/// `t x y z qx qy qz qw` lines; `#` comments and malformed lines are skipped. Sorted by stamp.
inline std::vector<StampedPose> ReadTum(const std::string& path) {
  std::vector<StampedPose> out;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    double t, x, y, z, qx, qy, qz, qw;
    if (std::sscanf(line.c_str(), "%lf %lf %lf %lf %lf %lf %lf %lf", &t, &x, &y, &z, &qx, &qy, &qz,
                    &qw) != 8)
      continue;
    StampedPose p;
    p.t = t;
    p.T.linear() = Eigen::Quaterniond(qw, qx, qy, qz).normalized().toRotationMatrix();
    p.T.translation() = Eigen::Vector3d(x, y, z);
    out.push_back(p);
  }
  std::sort(out.begin(), out.end(),
            [](const StampedPose& a, const StampedPose& b) { return a.t < b.t; });
  return out;
}

inline bool WriteTum(const std::string& path, const std::vector<StampedPose>& poses) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) return false;
  for (const StampedPose& s : poses) {
    const Eigen::Quaterniond q(s.T.linear());
    std::fprintf(f, "%.6f %.6f %.6f %.6f %.9f %.9f %.9f %.9f\n", s.t, s.T.translation().x(),
                 s.T.translation().y(), s.T.translation().z(), q.x(), q.y(), q.z(), q.w());
  }
  return std::fclose(f) == 0;
}

/// The pose nearest in time to `t`, or nullptr when none is within `max_dt`.
inline const StampedPose* Nearest(const std::vector<StampedPose>& tum, double t, double max_dt) {
  auto it = std::lower_bound(tum.begin(), tum.end(), t,
                             [](const StampedPose& s, double v) { return s.t < v; });
  const StampedPose* best = nullptr;
  for (auto c : {it, it == tum.begin() ? it : it - 1}) {
    if (c == tum.end()) continue;
    if (best == nullptr || std::fabs(c->t - t) < std::fabs(best->t - t)) best = &*c;
  }
  return best != nullptr && std::fabs(best->t - t) <= max_dt ? best : nullptr;
}

/// Interpolated pose at `t` (clamped to the ends).
inline Eigen::Isometry3d PoseAt(const std::vector<StampedPose>& tum, double t) {
  if (tum.empty()) return Eigen::Isometry3d::Identity();
  auto it = std::lower_bound(tum.begin(), tum.end(), t,
                             [](const StampedPose& s, double v) { return s.t < v; });
  if (it == tum.begin()) return tum.front().T;
  if (it == tum.end()) return tum.back().T;
  const StampedPose& b = *it;
  const StampedPose& a = *(it - 1);
  const double f = (t - a.t) / (b.t - a.t);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = a.T.translation() + f * (b.T.translation() - a.T.translation());
  T.linear() = Eigen::Quaterniond(a.T.linear())
                   .slerp(f, Eigen::Quaterniond(b.T.linear()))
                   .toRotationMatrix();
  return T;
}

struct AteResult {
  bool ok = false;
  const char* error = "";
  std::size_t poses = 0;  ///< associated pairs
  double rmse = 0, mean = 0, median = 0, max = 0;
  Eigen::Isometry3d T_truth_estimate = Eigen::Isometry3d::Identity();
};

inline AteResult ComputeAte(const std::vector<StampedPose>& estimate,
                            const std::vector<StampedPose>& truth,
                            double max_dt = 0.01) {
  std::vector<Eigen::Vector3d> a, b;
  for (const StampedPose& e : estimate) {
    if (const StampedPose* t = Nearest(truth, e.t, max_dt)) {
      a.push_back(e.T.translation());
      b.push_back(t->T.translation());
    }
  }
  AteResult out;
  out.poses = a.size();
  auto T = core::AlignUmeyama(a, b);
  if (!T) {
    out.error = T.error().detail;
    return out;
  }
  std::vector<double> errors;
  double sum = 0, sum2 = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const double e = (*T * a[i] - b[i]).norm();
    errors.push_back(e);
    sum += e;
    sum2 += e * e;
  }
  std::sort(errors.begin(), errors.end());
  const auto n = static_cast<double>(errors.size());
  out.rmse = std::sqrt(sum2 / n);
  out.mean = sum / n;
  out.median = errors[errors.size() / 2];
  out.max = errors.back();
  out.T_truth_estimate = *T;
  out.ok = true;
  return out;
}

}  // namespace msgraphs::tools
