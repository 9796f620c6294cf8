// SPDX-License-Identifier: MIT
// TUM trajectories for the host tools and tests (`t x y z qx qy qz qw`: seconds, metres,
// Hamilton quaternion; ../shared/spec/README.md section 4): read and write. The truth at an
// estimate's stamp is truth_pairing.hpp, the absolute trajectory error ate.hpp.
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

namespace msgraphs::tools {

struct StampedPose {
  double t = 0;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
};

/// `t x y z qx qy qz qw` lines; `#` comments, malformed lines and lines with a non-finite number
/// or a zero quaternion are skipped. Sorted by stamp.
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
    bool finite = true;
    for (double v : {t, x, y, z, qx, qy, qz, qw}) finite = finite && std::isfinite(v);
    const double q2 = qx * qx + qy * qy + qz * qz + qw * qw;
    if (!finite || !(q2 > 1e-12)) continue;
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

}  // namespace msgraphs::tools
