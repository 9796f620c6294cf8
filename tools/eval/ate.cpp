// SPDX-License-Identifier: MIT
// msgraphs_ate: absolute trajectory error of an estimate against ground truth, both in TUM
// format: every estimate pose paired with the truth interpolated at its stamp (position linear,
// rotation slerp between the bracketing samples; a stamp outside the truth's span, or between
// samples further apart than 2.5 median truth periods, stays unpaired and is counted), the
// estimate aligned to the truth by a rigid SE(3) Umeyama fit, then RMSE / mean / median / max of
// the position errors, as evo's `evo_ape tum --align` reports them.
//
//   msgraphs_ate --truth ground_truth.tum --estimate keyframes.tum [--max-dt-s S]
//                [--min-paired-fraction 0.5]
//
// --max-dt-s S: optional stricter limit, a pose is paired only when a truth sample lies within
// S seconds of its stamp (none by default). Exit 1 when fewer than 3 poses, or fewer than
// --min-paired-fraction of them (default half), are paired: the figure would not stand for the
// estimate.
#include "msgraphs/tools/ate.hpp"

#include <cstdio>
#include <cstdlib>
#include <string>

#include "msgraphs/tools/truth_pairing.hpp"
#include "msgraphs/tools/tum.hpp"

int main(int argc, char** argv) {
  std::string truth_path, estimate_path;
  msgraphs::tools::PairingConfig pairing;
  bool usage = false;
  for (int i = 1; i < argc && !usage; ++i) {
    const std::string a = argv[i];
    if (a == "--truth" && i + 1 < argc)
      truth_path = argv[++i];
    else if (a == "--estimate" && i + 1 < argc)
      estimate_path = argv[++i];
    else if (a == "--max-dt-s" && i + 1 < argc)
      pairing.max_dt_s = std::atof(argv[++i]);
    else if (a == "--min-paired-fraction" && i + 1 < argc)
      pairing.min_paired_fraction = std::atof(argv[++i]);
    else
      usage = true;
  }
  if (usage || truth_path.empty() || estimate_path.empty() || !(pairing.max_dt_s >= 0) ||
      !(pairing.min_paired_fraction >= 0 && pairing.min_paired_fraction <= 1)) {
    std::fprintf(stderr,
                 "usage: msgraphs_ate --truth TRUTH.tum --estimate ESTIMATE.tum [--max-dt-s S] "
                 "[--min-paired-fraction 0.5]\n");
    return 2;
  }
  const msgraphs::tools::TruthTrajectory truth(msgraphs::tools::ReadTum(truth_path), pairing);
  const auto estimate = msgraphs::tools::ReadTum(estimate_path);
  const auto ate = msgraphs::tools::ComputeAte(estimate, truth);
  std::printf(
      "truth: %zu samples, median period %.4f s, gap limit %.4f s; %zu of %zu poses paired "
      "(unpaired: %s)\n",
      truth.samples().size(), truth.median_period_s(), truth.gap_limit_s(), ate.pairs.paired,
      estimate.size(), ate.pairs.DescribeUnpaired().c_str());
  if (!ate.ok) {
    std::fprintf(stderr, "ate: %s (%zu paired poses)\n", ate.error, ate.pairs.paired);
    return 1;
  }
  std::printf("ATE over %zu poses: rmse %.4f m, mean %.4f m, median %.4f m, max %.4f m\n",
              ate.poses(), ate.rmse, ate.mean, ate.median, ate.max);
  return 0;
}
