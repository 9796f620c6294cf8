// SPDX-License-Identifier: MIT
// The ATE (tools/ate.hpp) against truth at any rate, and its paired / unpaired counts.
#include "msgraphs/tools/ate.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "analytic_trajectory.hpp"

namespace msgraphs::tools {
namespace {

using test::AnalyticPose;
using test::SampleTruth;

// 10 Hz keyframe stamps 37 ms after whole tenths (between the samples of every truth rate
// below), in the estimate's own frame, with a known 5 cm wobble: an ATE of a few centimetres.
std::vector<StampedPose> Estimate(double from_s, double to_s) {
  Eigen::Isometry3d T_estimate_world = Eigen::Isometry3d::Identity();
  T_estimate_world.linear() = Eigen::AngleAxisd(1.1, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T_estimate_world.translation() << 4, -2, 0.3;
  std::vector<StampedPose> out;
  for (double s = from_s + 0.037; s <= to_s; s += 0.1) {
    const double t = test::kT0 + s;
    Eigen::Isometry3d T = AnalyticPose(t);
    T.translation() += 0.05 * Eigen::Vector3d(std::sin(1.3 * s), std::cos(0.7 * s), 0);
    out.push_back({t, T_estimate_world * T});
  }
  return out;
}

TEST(Ate, TheSameAtEveryTruthRateWithinTheInterpolationBound) {
  const std::vector<StampedPose> estimate = Estimate(1, 59);
  // The exact ATE: the analytic truth at the estimate's own stamps.
  std::vector<StampedPose> exact;
  for (const StampedPose& e : estimate) exact.push_back({e.t, AnalyticPose(e.t)});
  std::vector<Eigen::Vector3d> a, b;
  for (std::size_t i = 0; i < estimate.size(); ++i) {
    a.push_back(estimate[i].T.translation());
    b.push_back(exact[i].T.translation());
  }
  const AteResult reference = AteOfPairs(a, b);
  ASSERT_TRUE(reference.ok);
  EXPECT_GT(reference.rmse, 0.02);
  for (double rate_hz : {10.0, 50.0, 100.0, 1000.0}) {
    const AteResult ate = ComputeAte(estimate, SampleTruth(rate_hz, 0, 60));
    ASSERT_TRUE(ate.ok) << rate_hz << ": " << ate.error;
    EXPECT_EQ(ate.pairs.paired, estimate.size()) << rate_hz;
    EXPECT_EQ(ate.pairs.unpaired_total(), 0u) << rate_hz;
    // Moving every truth point by at most e moves the aligned RMSE by at most e (it is a
    // minimum over rigid transforms of a norm), and linear interpolation moves it by at most
    // dt^2 / 8 * max|p''| (1.1 mm at 10 Hz), plus the stamps' resolution.
    const double dt = 1.0 / rate_hz;
    const double bound_m = dt * dt / 8.0 * test::kMaxAcceleration_m_s2 +
                           test::kMaxSpeed_m_s * test::kStampResolution_s;
    EXPECT_NEAR(ate.rmse, reference.rmse, bound_m) << rate_hz;
    EXPECT_NEAR(ate.max, reference.max, 2 * bound_m) << rate_hz;
  }
}

TEST(Ate, ReportsPairedAndUnpairedCounts) {
  // Estimate over 0-40 s, truth over 10-30 s: 100 keyframes before it, 100 after.
  const std::vector<StampedPose> estimate = Estimate(0, 40);
  const AteResult ate = ComputeAte(estimate, SampleTruth(50, 10, 30));
  ASSERT_TRUE(ate.ok) << ate.error;
  EXPECT_EQ(ate.pairs.paired, 200u);
  EXPECT_EQ(ate.pairs.count(Unpaired::kBeforeTruth), 100u);
  EXPECT_EQ(ate.pairs.count(Unpaired::kAfterTruth), 100u);
  EXPECT_EQ(ate.pairs.total(), estimate.size());
  EXPECT_EQ(ate.poses(), 200u);
}

TEST(Ate, FailsWhenMostPosesHaveNoTruth) {
  // Truth over 10-20 s of an estimate over 0-40 s: a quarter of it scored is not its ATE.
  const std::vector<StampedPose> estimate = Estimate(0, 40);
  const AteResult ate = ComputeAte(estimate, SampleTruth(50, 10, 20));
  EXPECT_FALSE(ate.ok);
  EXPECT_STREQ(ate.error,
               "fewer than min_paired_fraction (default half) of the poses paired with the truth");
  EXPECT_EQ(ate.pairs.paired, 100u);
  EXPECT_EQ(ate.pairs.count(Unpaired::kAfterTruth), 200u);
  // The fraction is a configuration value.
  PairingConfig lenient;
  lenient.min_paired_fraction = 0.2;
  EXPECT_TRUE(ComputeAte(estimate, SampleTruth(50, 10, 20), lenient).ok);
}

TEST(Ate, FailsWithTheReasonWhenTooFewPosesArePaired) {
  const std::vector<StampedPose> estimate = Estimate(20, 30);
  const AteResult ate = ComputeAte(estimate, SampleTruth(100, 0, 10));
  EXPECT_FALSE(ate.ok);
  EXPECT_STREQ(ate.error, "fewer than 3 poses paired with the truth");
  EXPECT_EQ(ate.pairs.paired, 0u);
  EXPECT_EQ(ate.pairs.count(Unpaired::kAfterTruth), estimate.size());
}

}  // namespace
}  // namespace msgraphs::tools
