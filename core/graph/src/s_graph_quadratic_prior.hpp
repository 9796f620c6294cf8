// SPDX-License-Identifier: MIT
// A quadratic x' H x - 2 g' x over a plane's x = [n; d] (ambient normal and offset) as a Ceres
// residual: r = L' x - c with H = L L' and L c = g, so that |r|^2 equals the quadratic up to a
// constant. The local solve sums a plane's observations by held keyframes into one (exact: with
// the keyframe held, an observation's residual is linear in the plane). Private to core_graph.
#pragma once

#include <ceres/sized_cost_function.h>

#include <Eigen/Eigenvalues>
#include <memory>

namespace msgraphs::core::sgraph {

class QuadraticPrior final : public ceres::SizedCostFunction<4, 3, 1> {
 public:
  /// Null when H has no positive direction. Directions whose eigenvalue is below 1e-12 of the
  /// largest carry nothing and are dropped (g has no component there: every term of g lies in
  /// the span of H's).
  static std::unique_ptr<QuadraticPrior> FromNormalEquations(const Eigen::Matrix4d& H,
                                                             const Eigen::Vector4d& g) {
    if (!H.allFinite() || !g.allFinite()) return nullptr;
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> eigen(0.5 * (H + H.transpose()));
    if (eigen.info() != Eigen::Success) return nullptr;
    const double largest = eigen.eigenvalues().maxCoeff();
    if (!(largest > 0)) return nullptr;
    auto prior = std::unique_ptr<QuadraticPrior>(new QuadraticPrior);
    for (int i = 0; i < 4; ++i) {
      const double lambda = eigen.eigenvalues()[i];
      if (!(lambda > 1e-12 * largest)) continue;  // rows stay zero
      const Eigen::Vector4d v = eigen.eigenvectors().col(i);
      prior->rows_.row(i) = std::sqrt(lambda) * v.transpose();
      prior->c_[i] = v.dot(g) / std::sqrt(lambda);
    }
    return prior;
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const Eigen::Vector4d x(parameters[0][0], parameters[0][1], parameters[0][2],
                            parameters[1][0]);
    Eigen::Map<Eigen::Vector4d> r(residuals);
    r = rows_ * x - c_;
    if (jacobians == nullptr) return true;
    if (jacobians[0] != nullptr) {
      Eigen::Map<Eigen::Matrix<double, 4, 3, Eigen::RowMajor>> J_n(jacobians[0]);
      J_n = rows_.leftCols<3>();
    }
    if (jacobians[1] != nullptr) {
      Eigen::Map<Eigen::Vector4d> J_d(jacobians[1]);
      J_d = rows_.col(3);
    }
    return true;
  }

 private:
  QuadraticPrior() = default;
  Eigen::Matrix4d rows_ = Eigen::Matrix4d::Zero();
  Eigen::Vector4d c_ = Eigen::Vector4d::Zero();
};

}  // namespace msgraphs::core::sgraph
