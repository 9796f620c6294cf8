// SPDX-License-Identifier: MIT
// msgraphs_ate: absolute trajectory error of an estimate against ground truth, both in TUM
// format: poses associated by timestamp (within --max-dt-s), the estimate aligned to the truth
// by a rigid SE(3) Umeyama fit, then RMSE / mean / median / max of the position errors, as evo's
// `evo_ape tum --align` reports them.
//
//   msgraphs_ate --truth ground_truth.tum --estimate odometry.tum [--max-dt-s 0.01]
#include <cstdio>
#include <cstdlib>
#include <string>

#include "msgraphs/tools/tum.hpp"

int main(int argc, char** argv) {
  std::string truth_path, estimate_path;
  double max_dt = 0.01;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--truth")
      truth_path = argv[i + 1];
    else if (a == "--estimate")
      estimate_path = argv[i + 1];
    else if (a == "--max-dt-s")
      max_dt = std::atof(argv[i + 1]);
  }
  if (truth_path.empty() || estimate_path.empty()) {
    std::fprintf(
        stderr,
        "usage: msgraphs_ate --truth TRUTH.tum --estimate ESTIMATE.tum [--max-dt-s 0.01]\n");
    return 2;
  }
  const auto ate = msgraphs::tools::ComputeAte(msgraphs::tools::ReadTum(estimate_path),
                                               msgraphs::tools::ReadTum(truth_path), max_dt);
  if (!ate.ok) {
    std::fprintf(stderr, "ate: %s (%zu associated poses)\n", ate.error, ate.poses);
    return 1;
  }
  std::printf("ATE over %zu poses: rmse %.4f m, mean %.4f m, median %.4f m, max %.4f m\n",
              ate.poses, ate.rmse, ate.mean, ate.median, ate.max);
  return 0;
}
