// SPDX-License-Identifier: MIT
// A view's aggregated ATE (tools/aggregated_ate.hpp): every robot is listed, and a merged robot
// without truth at its keyframes fails the figure instead of leaving it.
#include "msgraphs/tools/aggregated_ate.hpp"

#include <gtest/gtest.h>

#include <vector>

#include "analytic_trajectory.hpp"

namespace msgraphs::tools {
namespace {

using test::SampleTruth;

std::vector<StampedPose> Keyframes(double from_s, double to_s) {
  std::vector<StampedPose> out;
  for (double s = from_s + 0.043; s <= to_s; s += 0.5) {
    out.push_back({test::kT0 + s, test::AnalyticPose(test::kT0 + s)});
  }
  return out;
}

TEST(AggregatedAte, EveryMergedRobotWithTruthIsAMember) {
  const TruthTrajectory truth1(SampleTruth(50, 0, 30)), truth2(SampleTruth(50, 0, 30));
  AggregatedAteBuilder view;
  view.AddMerged(1, Keyframes(1, 29), &truth1);
  view.AddMerged(2, Keyframes(1, 29), &truth2);
  view.AddNotMerged(3);
  const AggregatedAte a = view.Finish();
  EXPECT_TRUE(a.ok()) << a.failure();
  ASSERT_EQ(a.members.size(), 2u);
  EXPECT_EQ(a.ate.pairs.paired, 2 * Keyframes(1, 29).size());
  EXPECT_LT(a.ate.rmse, 1e-3);
  // The robot that was not merged is listed, but does not fail the ATE of what was merged.
  ASSERT_EQ(a.missing.size(), 1u);
  EXPECT_EQ(a.missing[0].robot, 3);
  EXPECT_FALSE(a.missing[0].merged);
  EXPECT_NE(a.Describe().find("missing: robot 3 (not merged)"), std::string::npos);
}

TEST(AggregatedAte, AMergedRobotWithoutPairedPosesIsReportedAndFailsTheFigure) {
  const TruthTrajectory truth1(SampleTruth(50, 0, 30));
  // Robot 2's truth ends before its first keyframe: none of its keyframes can be scored.
  const TruthTrajectory truth2(SampleTruth(50, 0, 5));
  AggregatedAteBuilder view;
  view.AddMerged(1, Keyframes(1, 29), &truth1);
  view.AddMerged(2, Keyframes(10, 29), &truth2);
  view.AddMerged(3, Keyframes(1, 29), nullptr);
  const AggregatedAte a = view.Finish();
  EXPECT_TRUE(a.ate.ok);  // robot 1 alone aligns...
  EXPECT_FALSE(a.ok());   // ...but the figure does not stand for the view
  EXPECT_TRUE(a.truth_incomplete());
  ASSERT_EQ(a.members.size(), 1u);
  EXPECT_EQ(a.members[0].robot, 1);
  ASSERT_EQ(a.missing.size(), 2u);
  EXPECT_EQ(a.missing[0].robot, 2);
  EXPECT_TRUE(a.missing[0].merged);
  EXPECT_NE(a.missing[0].reason.find("has 0 of 38 keyframes paired"), std::string::npos)
      << a.missing[0].reason;
  EXPECT_NE(a.missing[0].reason.find("38 after the truth"), std::string::npos);
  EXPECT_EQ(a.missing[1].reason, "has no ground truth");
  EXPECT_NE(a.failure().find("robot 2 merged but has 0 of 38"), std::string::npos) << a.failure();
  EXPECT_NE(a.failure().find("robot 3 merged but has no ground truth"), std::string::npos);
}

TEST(AggregatedAte, ARobotScoredOverAFewOfItsKeyframesFailsTheFigure) {
  const TruthTrajectory truth1(SampleTruth(50, 0, 30));
  const TruthTrajectory truth2(SampleTruth(50, 0, 3));  // 4 of robot 2's 56 keyframes
  AggregatedAteBuilder view;
  view.AddMerged(1, Keyframes(1, 29), &truth1);
  view.AddMerged(2, Keyframes(1, 29), &truth2);
  const AggregatedAte a = view.Finish();
  EXPECT_FALSE(a.ok());
  ASSERT_EQ(a.missing.size(), 1u);
  EXPECT_NE(a.missing[0].reason.find("has 4 of 56 keyframes paired"), std::string::npos)
      << a.missing[0].reason;
}

TEST(AggregatedAte, NoMemberAtAllFailsWithTheReason) {
  const TruthTrajectory truth(SampleTruth(10, 100, 110));
  AggregatedAteBuilder view;
  view.AddMerged(1, Keyframes(1, 29), &truth);  // every keyframe before the truth
  const AggregatedAte a = view.Finish();
  EXPECT_FALSE(a.ate.ok);
  EXPECT_FALSE(a.ok());
  EXPECT_NE(a.failure().find("before the truth"), std::string::npos) << a.failure();
}

}  // namespace
}  // namespace msgraphs::tools
