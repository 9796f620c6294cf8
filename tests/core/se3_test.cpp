// SPDX-License-Identifier: MIT
#include "msgraphs/core/geometry/se3.hpp"
#include "msgraphs/core/geometry/umeyama.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

namespace msgraphs::core {
namespace {

Vector6d Xi(double a, double b, double c, double d, double e, double f) {
  Vector6d xi;
  xi << a, b, c, d, e, f;
  return xi;
}

TEST(Se3, ExpLogRoundTripOverTheWholeRange) {
  const double pi = std::numbers::pi;
  // Small, moderate, close to pi and exactly pi rotations.
  for (const double angle : {0.0, 1e-9, 1e-4, 0.5, 2.0, pi - 1e-7, pi}) {
    const Eigen::Vector3d axis = Eigen::Vector3d(1.0, -2.0, 0.5).normalized();
    const Vector6d xi = Xi(0.3, -1.2, 2.0, angle * axis.x(), angle * axis.y(), angle * axis.z());
    const Eigen::Isometry3d T = Se3Exp(xi);
    EXPECT_TRUE(IsValidRigidTransform(T)) << angle;
    const Eigen::Isometry3d T_back = Se3Exp(Se3Log(T));
    EXPECT_LT((T_back.matrix() - T.matrix()).cwiseAbs().maxCoeff(), 1e-9) << angle;
  }
}

TEST(Se3, ExpOfPureTranslationIsTranslation) {
  const Eigen::Isometry3d T = Se3Exp(Xi(1.0, 2.0, 3.0, 0.0, 0.0, 0.0));
  EXPECT_TRUE(T.linear().isIdentity(1e-15));
  EXPECT_TRUE(T.translation().isApprox(Eigen::Vector3d(1.0, 2.0, 3.0)));
}

TEST(Se3, LeftJacobianAndInverseAreInverses) {
  for (const double angle : {0.0, 1e-8, 0.3, 3.0}) {
    const Eigen::Vector3d phi = angle * Eigen::Vector3d(0.0, 0.6, 0.8);
    const Eigen::Matrix3d prod = So3LeftJacobian(phi) * So3LeftJacobianInverse(phi);
    EXPECT_TRUE(prod.isIdentity(1e-9)) << angle;
  }
}

TEST(Se3, InterpolationEndsAndMidpoint) {
  Eigen::Isometry3d T_a = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d T_b = Eigen::Isometry3d::Identity();
  T_b.linear() = RotZ(std::numbers::pi / 2);
  T_b.translation() = Eigen::Vector3d(2.0, 0.0, 0.0);
  EXPECT_TRUE(Interpolate(T_a, T_b, 0.0).isApprox(T_a, 1e-12));
  EXPECT_TRUE(Interpolate(T_a, T_b, 1.0).isApprox(T_b, 1e-12));
  const Eigen::Isometry3d mid = Interpolate(T_a, T_b, 0.5);
  EXPECT_NEAR(So3Log(mid.linear()).z(), std::numbers::pi / 4, 1e-12);
}

TEST(Se3, RejectsInvalidTransforms) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  EXPECT_TRUE(IsValidRigidTransform(T));
  T.translation().x() = std::nan("");
  EXPECT_FALSE(IsValidRigidTransform(T));
  T = Eigen::Isometry3d::Identity();
  T.linear()(0, 0) = -1.0;  // a reflection: orthonormal but det -1
  EXPECT_FALSE(IsValidRigidTransform(T));
  T = Eigen::Isometry3d::Identity();
  T.linear() *= 1.01;  // scaled
  EXPECT_FALSE(IsValidRigidTransform(T));
}

}  // namespace
}  // namespace msgraphs::core


namespace msgraphs::core {
namespace {

TEST(Umeyama, RecoversARigidTransformAndRefusesDegenerateSets) {
  const Eigen::Isometry3d truth = Eigen::Translation3d(1, -2, 0.5) * Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized());
  std::vector<Eigen::Vector3d> a, b;
  for (int i = 0; i < 20; ++i) {
    a.emplace_back(std::sin(i), std::cos(3.0 * i), 0.1 * i);
    b.push_back(truth * a.back());
  }
  const auto T = AlignUmeyama(a, b);
  ASSERT_TRUE(T.has_value());
  EXPECT_LT((T->matrix() - truth.matrix()).norm(), 1e-9);
  std::vector<Eigen::Vector3d> line = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  EXPECT_EQ(AlignUmeyama(line, line).error().code, Errc::kDegenerate);
  EXPECT_EQ(AlignUmeyama(std::span(a).first(2), std::span(b).first(2)).error().code, Errc::kDegenerate);
  EXPECT_EQ(AlignUmeyama(a, std::span(b).first(5)).error().code, Errc::kInvalidArgument);
}

}  // namespace
}  // namespace msgraphs::core
