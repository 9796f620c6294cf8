// SPDX-License-Identifier: MIT
// The truth at an estimate's stamp (tools/truth_pairing.hpp): interpolation of a known analytic
// trajectory at any truth rate, and every stamp that cannot be paired counted with its reason.
#include "msgraphs/tools/truth_pairing.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "analytic_trajectory.hpp"

namespace msgraphs::tools {
namespace {

using test::AnalyticPose;
using test::SampleTruth;

TEST(TruthPairing, MedianPeriodAndGapLimitComeFromTheTruth) {
  for (double rate_hz : {10.0, 50.0, 100.0, 1000.0}) {
    const TruthTrajectory truth(SampleTruth(rate_hz, 0, 20));
    EXPECT_NEAR(truth.median_period_s(), 1.0 / rate_hz, 1e-6) << rate_hz;
    EXPECT_NEAR(truth.gap_limit_s(), 2.5 / rate_hz, 1e-6) << rate_hz;
  }
}

TEST(TruthPairing, PositionIsWithinTheLinearInterpolationBoundAtEveryRate) {
  // Linear interpolation between samples dt apart is off by at most dt^2 / 8 * max|p''|.
  for (double rate_hz : {10.0, 50.0, 100.0, 1000.0}) {
    const TruthTrajectory truth(SampleTruth(rate_hz, 0, 30));
    const double dt = 1.0 / rate_hz;
    const double bound_m = dt * dt / 8.0 * test::kMaxAcceleration_m_s2 +
                           test::kMaxSpeed_m_s * test::kStampResolution_s;
    double worst_m = 0;
    for (double t = test::kT0 + 1.0137; t < test::kT0 + 29; t += 0.0731) {
      const auto l = truth.At(t);
      ASSERT_TRUE(l.ok) << rate_hz << " " << t;
      worst_m = std::max(worst_m, (l.T.translation() - AnalyticPose(t).translation()).norm());
    }
    EXPECT_LE(worst_m, bound_m) << rate_hz;
    EXPECT_GT(worst_m, 0.0) << rate_hz;  // the samples really are apart from the stamps
  }
}

TEST(TruthPairing, RotationIsSlerpedBetweenTheBracketingSamples) {
  // About one axis at a constant rate, slerp is exact at any rate.
  std::vector<StampedPose> yaw_only;
  for (int i = 0; i <= 100; ++i) {
    const double t = 10.0 + 0.1 * i;
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::AngleAxisd(0.7 * t, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    yaw_only.push_back({t, T});
  }
  const TruthTrajectory truth(yaw_only);
  for (double t = 10.013; t < 19.9; t += 0.0377) {
    const auto l = truth.At(t);
    ASSERT_TRUE(l.ok);
    const Eigen::Matrix3d want =
        Eigen::AngleAxisd(0.7 * t, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    EXPECT_LT(Eigen::AngleAxisd(want.transpose() * l.T.linear()).angle(), 1e-9) << t;
  }
  // Rolling, pitching and yawing at varying rates: the error shrinks with the square of the
  // period (nearest-sample lookup would only shrink linearly: ~0.04 rad at 10 Hz).
  double previous_rad = 0;  // at 10 Hz
  for (double rate_hz : {10.0, 100.0, 1000.0}) {
    const TruthTrajectory sampled(SampleTruth(rate_hz, 0, 30));
    double worst_rad = 0;
    for (double t = test::kT0 + 1.0137; t < test::kT0 + 29; t += 0.0731) {
      const auto l = sampled.At(t);
      ASSERT_TRUE(l.ok);
      worst_rad =
          std::max(worst_rad,
                   Eigen::AngleAxisd(AnalyticPose(t).linear().transpose() * l.T.linear()).angle());
    }
    const double dt = 1.0 / rate_hz;
    EXPECT_LE(worst_rad, dt * dt / 8.0 * test::kMaxAngularBound_rad_s2 +
                             test::kMaxRate_rad_s * test::kStampResolution_s)
        << rate_hz;
    if (rate_hz == 100.0) {
      EXPECT_LT(worst_rad, previous_rad / 50);  // 10x the rate
    }
    previous_rad = worst_rad;
  }
}

TEST(TruthPairing, StampsOutsideTheTruthOrInAGapAreCountedWithTheirReason) {
  // 100 Hz from t = 100 to 110, without (104.0, 104.5) and without the lone sample at 106.00.
  std::vector<StampedPose> samples;
  for (int i = 0; i <= 1000; ++i) {
    const double t = 100.0 + 0.01 * i;
    if ((t > 104.0 + 1e-9 && t < 104.5 - 1e-9) || i == 600) continue;
    samples.push_back({t, AnalyticPose(t)});
  }
  const TruthTrajectory truth(samples);
  EXPECT_NEAR(truth.median_period_s(), 0.01, 1e-9);  // the gaps do not move the median

  const std::vector<StampedPose> estimate = {
      {99.9},     // before the first sample
      {100.0},    // exactly the first sample: paired
      {104.2},    // in the half-second gap
      {104.5},    // exactly the sample that ends the gap: paired
      {105.996},  // one lone missing sample is bridged (2 periods < 2.5)
      {110.0},    // exactly the last sample: paired
      {110.05},   // after the last sample
      {std::numeric_limits<double>::quiet_NaN()},
  };
  const PairedPoses paired = PairWithTruth(estimate, truth);
  EXPECT_EQ(paired.counts.paired, 4u);
  EXPECT_EQ(paired.counts.count(Unpaired::kBeforeTruth), 1u);
  EXPECT_EQ(paired.counts.count(Unpaired::kAfterTruth), 1u);
  EXPECT_EQ(paired.counts.count(Unpaired::kInGap), 1u);
  EXPECT_EQ(paired.counts.count(Unpaired::kBadStamp), 1u);
  EXPECT_EQ(paired.counts.total(), estimate.size());
  ASSERT_EQ(paired.estimate.size(), 4u);
  EXPECT_EQ(paired.estimate[2].t, 105.996);
  EXPECT_LT((paired.truth[2].T.translation() - AnalyticPose(105.996).translation()).norm(), 1e-3);
  EXPECT_EQ(paired.counts.DescribeUnpaired(),
            "1 before the truth, 1 after the truth, 1 in a gap of the truth, 1 non-finite stamp");
}

TEST(TruthPairing, MaxDtIsAnOptionalStricterLimit) {
  PairingConfig strict;
  strict.max_dt_s = 0.02;
  const TruthTrajectory truth(SampleTruth(10, 0, 5), strict);
  EXPECT_TRUE(truth.At(test::kT0 + 1.015).ok);  // 15 ms from a sample
  const auto far = truth.At(test::kT0 + 1.05);  // 50 ms from both
  EXPECT_FALSE(far.ok);
  EXPECT_EQ(far.reason, Unpaired::kBeyondMaxDt);
  EXPECT_TRUE(TruthTrajectory(SampleTruth(10, 0, 5)).At(test::kT0 + 1.05).ok);  // default: none
}

TEST(TruthPairing, TooLittleTruthPairsNothing) {
  EXPECT_EQ(TruthTrajectory().At(1.0).reason, Unpaired::kNoTruth);
  const TruthTrajectory one(std::vector<StampedPose>{{1.0, Eigen::Isometry3d::Identity()}});
  EXPECT_EQ(one.At(1.0).reason, Unpaired::kNoTruth);
  // Only duplicate stamps: no period to derive a gap limit from.
  const TruthTrajectory duplicates(std::vector<StampedPose>{{1.0}, {1.0}});
  EXPECT_EQ(duplicates.At(1.0).reason, Unpaired::kNoTruth);
}

}  // namespace
}  // namespace msgraphs::tools
