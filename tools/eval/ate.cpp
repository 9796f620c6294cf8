// SPDX-License-Identifier: MIT
// msgraphs_ate: absolute trajectory error of an estimate against ground truth, both in TUM
// format: poses associated by timestamp (within --max-dt-s), the estimate aligned to the truth
// by a rigid SE(3) Umeyama fit, then RMSE / mean / median / max of the position errors, as evo's
// `evo_ape tum --align` reports them.
//
//   msgraphs_ate --truth ground_truth.tum --estimate odometry.tum [--max-dt-s 0.01]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include "msgraphs/core/geometry/umeyama.hpp"

namespace {

struct Pose {
  double t;
  Eigen::Vector3d p;
};

std::vector<Pose> Read(const std::string& path) {
  std::vector<Pose> out;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    double t, x, y, z, qx, qy, qz, qw;
    if (std::sscanf(line.c_str(), "%lf %lf %lf %lf %lf %lf %lf %lf", &t, &x, &y, &z, &qx, &qy, &qz, &qw) == 8) {
      out.push_back({t, {x, y, z}});
    }
  }
  std::sort(out.begin(), out.end(), [](const Pose& a, const Pose& b) { return a.t < b.t; });
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  std::string truth_path, estimate_path;
  double max_dt = 0.01;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--truth") truth_path = argv[i + 1];
    else if (a == "--estimate") estimate_path = argv[i + 1];
    else if (a == "--max-dt-s") max_dt = std::atof(argv[i + 1]);
  }
  if (truth_path.empty() || estimate_path.empty()) {
    std::fprintf(stderr, "usage: msgraphs_ate --truth TRUTH.tum --estimate ESTIMATE.tum [--max-dt-s 0.01]\n");
    return 2;
  }
  const auto truth = Read(truth_path);
  const auto estimate = Read(estimate_path);
  std::vector<Eigen::Vector3d> a, b;
  for (const Pose& e : estimate) {
    auto it = std::lower_bound(truth.begin(), truth.end(), e.t, [](const Pose& p, double t) { return p.t < t; });
    const Pose* best = nullptr;
    for (auto c : {it, it == truth.begin() ? it : it - 1}) {
      if (c == truth.end()) continue;
      if (best == nullptr || std::fabs(c->t - e.t) < std::fabs(best->t - e.t)) best = &*c;
    }
    if (best == nullptr || std::fabs(best->t - e.t) > max_dt) continue;
    a.push_back(e.p);
    b.push_back(best->p);
  }
  auto T = msgraphs::core::AlignUmeyama(a, b);
  if (!T) {
    std::fprintf(stderr, "ate: %s (%zu associated poses)\n", T.error().detail, a.size());
    return 1;
  }
  std::vector<double> errors;
  double sum2 = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const double e = (*T * a[i] - b[i]).norm();
    errors.push_back(e);
    sum2 += e * e;
  }
  std::sort(errors.begin(), errors.end());
  double mean = 0;
  for (double e : errors) mean += e;
  mean /= static_cast<double>(errors.size());
  std::printf("ATE over %zu poses: rmse %.4f m, mean %.4f m, median %.4f m, max %.4f m\n", errors.size(),
              std::sqrt(sum2 / static_cast<double>(errors.size())), mean, errors[errors.size() / 2], errors.back());
  return 0;
}
