// SPDX-License-Identifier: MIT
#include "msgraphs/core/graph/pose_graph_optimizer.hpp"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <cmath>
#include <queue>

namespace msgraphs::core {
namespace {

// ---- chordal relaxation: rotations -------------------------------------------------------------

template <int D>
struct ChordalRotationResidual {
  Eigen::Matrix<double, D, D> R_ij;
  double sqrt_kappa;
  template <typename T>
  bool operator()(const T* mi, const T* mj, T* r) const {
    Eigen::Map<const Eigen::Matrix<T, D, D, Eigen::RowMajor>> Mi(mi), Mj(mj);
    Eigen::Map<Eigen::Matrix<T, D, D, Eigen::RowMajor>> res(r);
    res = (Mj - Mi * R_ij.template cast<T>()) * T(sqrt_kappa);
    return true;
  }
};

template <int D>
struct ChordalTranslationResidual {
  Eigen::Matrix<double, D, D> R_i;
  Eigen::Matrix<double, D, 1> t_ij;
  double sqrt_tau;
  template <typename T>
  bool operator()(const T* ti, const T* tj, T* r) const {
    Eigen::Map<const Eigen::Matrix<T, D, 1>> a(ti), b(tj);
    Eigen::Map<Eigen::Matrix<T, D, 1>> res(r);
    res = (b - a - (R_i * t_ij).template cast<T>()) * T(sqrt_tau);
    return true;
  }
};

// ---- the SE-Sync objective as residuals (3-D: quaternion + translation) -------------------------

struct ChordalSE3 {
  Eigen::Matrix3d R_ij;
  Eigen::Vector3d t_ij;
  double sqrt_kappa, sqrt_tau;
  template <typename T>
  bool operator()(const T* qi, const T* ti, const T* qj, const T* tj, T* r) const {
    const Eigen::Matrix<T, 3, 3> Ri = Eigen::Map<const Eigen::Quaternion<T>>(qi).toRotationMatrix();
    const Eigen::Matrix<T, 3, 3> Rj = Eigen::Map<const Eigen::Quaternion<T>>(qj).toRotationMatrix();
    Eigen::Map<Eigen::Matrix<T, 3, 3, Eigen::RowMajor>> rr(r);
    rr = (Rj - Ri * R_ij.cast<T>()) * T(sqrt_kappa);
    Eigen::Map<Eigen::Matrix<T, 3, 1>> rt(r + 9);
    rt = (Eigen::Map<const Eigen::Matrix<T, 3, 1>>(tj) - Eigen::Map<const Eigen::Matrix<T, 3, 1>>(ti) -
          Ri * t_ij.cast<T>()) *
         T(sqrt_tau);
    return true;
  }
};

struct ChordalSE2 {
  Eigen::Matrix2d R_ij;
  Eigen::Vector2d t_ij;
  double sqrt_kappa, sqrt_tau;
  template <typename T>
  bool operator()(const T* thi, const T* ti, const T* thj, const T* tj, T* r) const {
    Eigen::Matrix<T, 2, 2> Ri, Rj;
    Ri << cos(thi[0]), -sin(thi[0]), sin(thi[0]), cos(thi[0]);
    Rj << cos(thj[0]), -sin(thj[0]), sin(thj[0]), cos(thj[0]);
    Eigen::Map<Eigen::Matrix<T, 2, 2, Eigen::RowMajor>> rr(r);
    rr = (Rj - Ri * R_ij.cast<T>()) * T(sqrt_kappa);
    Eigen::Map<Eigen::Matrix<T, 2, 1>> rt(r + 4);
    rt = (Eigen::Map<const Eigen::Matrix<T, 2, 1>>(tj) - Eigen::Map<const Eigen::Matrix<T, 2, 1>>(ti) -
          Ri * t_ij.cast<T>()) *
         T(sqrt_tau);
    return true;
  }
};

// ---- g2o / MRPT chi^2 --------------------------------------------------------------------------

struct GeodesicSE3 {
  Eigen::Quaterniond q_ij;
  Eigen::Vector3d t_ij;
  Eigen::Matrix<double, 6, 6> sqrt_information;  // upper Cholesky factor
  template <typename T>
  bool operator()(const T* qi, const T* ti, const T* qj, const T* tj, T* r) const {
    const Eigen::Quaternion<T> Qi = Eigen::Map<const Eigen::Quaternion<T>>(qi);
    const Eigen::Quaternion<T> Qj = Eigen::Map<const Eigen::Quaternion<T>>(qj);
    const Eigen::Matrix<T, 3, 1> Ti = Eigen::Map<const Eigen::Matrix<T, 3, 1>>(ti);
    const Eigen::Matrix<T, 3, 1> Tj = Eigen::Map<const Eigen::Matrix<T, 3, 1>>(tj);
    // Measured against estimated relative pose: E = Z^-1 (Xi^-1 Xj).
    const Eigen::Quaternion<T> Qij = Qi.conjugate() * Qj;
    const Eigen::Matrix<T, 3, 1> tij = Qi.conjugate() * (Tj - Ti);
    const Eigen::Quaternion<T> Qz = q_ij.cast<T>();
    const Eigen::Quaternion<T> dq = Qz.conjugate() * Qij;
    const Eigen::Matrix<T, 3, 1> dt = Qz.conjugate() * (tij - t_ij.cast<T>());
    Eigen::Matrix<T, 6, 1> e;
    e.template head<3>() = dt;
    T axis[3];
    const T quat[4] = {dq.w(), dq.x(), dq.y(), dq.z()};
    ceres::QuaternionToAngleAxis(quat, axis);
    e.template tail<3>() << axis[0], axis[1], axis[2];
    Eigen::Map<Eigen::Matrix<T, 6, 1>> res(r);
    res = sqrt_information.cast<T>() * e;
    return true;
  }
};

struct GeodesicSE2 {
  double x, y, theta;
  Eigen::Matrix3d sqrt_information;
  template <typename T>
  bool operator()(const T* thi, const T* ti, const T* thj, const T* tj, T* r) const {
    // Relative pose of j in i, then its difference from the measurement in the measurement frame.
    const T c = cos(thi[0]), s = sin(thi[0]);
    const T dx = tj[0] - ti[0], dy = tj[1] - ti[1];
    const T rx = c * dx + s * dy, ry = -s * dx + c * dy;
    const T cz = T(std::cos(theta)), sz = T(std::sin(theta));
    const T ex = cz * (rx - T(x)) + sz * (ry - T(y));
    const T ey = -sz * (rx - T(x)) + cz * (ry - T(y));
    T eth = thj[0] - thi[0] - T(theta);
    eth = atan2(sin(eth), cos(eth));
    const Eigen::Matrix<T, 3, 1> e(ex, ey, eth);
    Eigen::Map<Eigen::Matrix<T, 3, 1>> res(r);
    res = sqrt_information.cast<T>() * e;
    return true;
  }
};

// The square root of an information matrix for residual weighting; indefinite matrices (some
// public graphs have them) are projected onto the positive semidefinite cone first.
template <int N>
Eigen::Matrix<double, N, N> SqrtInformation(const Eigen::Matrix<double, N, N>& info) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, N, N>> eig(0.5 * (info + info.transpose()));
  const Eigen::Matrix<double, N, 1> root = eig.eigenvalues().cwiseMax(0.0).cwiseSqrt();
  return root.asDiagonal() * eig.eigenvectors().transpose();
}

template <int D>
Eigen::Matrix<double, D, D> ProjectToSO(const Eigen::Matrix<double, D, D>& M) {
  Eigen::JacobiSVD<Eigen::Matrix<double, D, D>> svd(M, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix<double, D, D> S = Eigen::Matrix<double, D, D>::Identity();
  if ((svd.matrixU() * svd.matrixV().transpose()).determinant() < 0) S(D - 1, D - 1) = -1;
  return svd.matrixU() * S * svd.matrixV().transpose();
}

std::vector<std::uint32_t> GaugeVertices(const PoseGraph& g) {
  if (!g.fixed.empty()) return g.fixed;
  return {0};
}

ceres::Solver::Options SolverOptions(int iterations, double ftol, double gtol, double ptol) {
  ceres::Solver::Options o;
  o.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  // Powell's dog leg takes Gauss-Newton steps when they work; on torus3D it needs a third of the
  // iterations Levenberg-Marquardt needs (each a sparse Cholesky factorisation).
  o.trust_region_strategy_type = ceres::DOGLEG;
  o.max_num_iterations = iterations;
  o.function_tolerance = ftol;
  o.gradient_tolerance = gtol;
  o.parameter_tolerance = ptol;
  o.num_threads = 1;  // core owns no threads
  o.logging_type = ceres::SILENT;
  o.minimizer_progress_to_stdout = false;
  return o;
}

template <int D>
Status ChordalInitialise(PoseGraph& g) {
  const std::size_t n = g.poses.size();
  // Rotations: unconstrained D x D matrices, row-major.
  std::vector<double> M(n * D * D, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    for (int k = 0; k < D; ++k) M[i * D * D + static_cast<std::size_t>(k * D + k)] = 1.0;
  }
  {
    ceres::Problem problem;
    for (const PoseGraphEdge& e : g.edges) {
      double kappa = 0, tau = 0;
      SeSyncWeights(e, g.planar, kappa, tau);
      auto* f = new ChordalRotationResidual<D>{e.T_from_to.linear().topLeftCorner<D, D>(), std::sqrt(kappa)};
      problem.AddResidualBlock(new ceres::AutoDiffCostFunction<ChordalRotationResidual<D>, D * D, D * D, D * D>(f),
                               nullptr, &M[e.from * D * D], &M[e.to * D * D]);
    }
    for (std::uint32_t v : GaugeVertices(g)) {
      if (problem.HasParameterBlock(&M[v * D * D])) problem.SetParameterBlockConstant(&M[v * D * D]);
    }
    ceres::Solver::Summary summary;
    ceres::Solve(SolverOptions(5, 1e-16, 1e-16, 1e-16), &problem, &summary);
    if (!summary.IsSolutionUsable()) return Error{Errc::kNotConverged, "pose graph: chordal rotation solve failed"};
  }
  std::vector<Eigen::Matrix<double, D, D>> R(n);
  for (std::size_t i = 0; i < n; ++i) {
    R[i] = ProjectToSO<D>(Eigen::Map<const Eigen::Matrix<double, D, D, Eigen::RowMajor>>(&M[i * D * D]));
  }
  // Translations given the rotations.
  std::vector<double> t(n * D, 0.0);
  {
    ceres::Problem problem;
    for (const PoseGraphEdge& e : g.edges) {
      double kappa = 0, tau = 0;
      SeSyncWeights(e, g.planar, kappa, tau);
      auto* f = new ChordalTranslationResidual<D>{R[e.from], e.T_from_to.translation().head<D>(), std::sqrt(tau)};
      problem.AddResidualBlock(new ceres::AutoDiffCostFunction<ChordalTranslationResidual<D>, D, D, D>(f), nullptr,
                               &t[e.from * D], &t[e.to * D]);
    }
    for (std::uint32_t v : GaugeVertices(g)) {
      if (problem.HasParameterBlock(&t[v * D])) problem.SetParameterBlockConstant(&t[v * D]);
    }
    ceres::Solver::Summary summary;
    ceres::Solve(SolverOptions(5, 1e-16, 1e-16, 1e-16), &problem, &summary);
    if (!summary.IsSolutionUsable()) return Error{Errc::kNotConverged, "pose graph: chordal translation solve failed"};
  }
  for (std::size_t i = 0; i < n; ++i) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear().topLeftCorner<D, D>() = R[i];
    T.translation().head<D>() = Eigen::Map<const Eigen::Matrix<double, D, 1>>(&t[i * D]);
    g.poses[i] = T;
  }
  return Ok();
}

Status SpanningTree(PoseGraph& g) {
  const std::size_t n = g.poses.size();
  std::vector<std::vector<std::pair<std::size_t, bool>>> adjacent(n);  // edge index, forward
  for (std::size_t k = 0; k < g.edges.size(); ++k) {
    adjacent[g.edges[k].from].push_back({k, true});
    adjacent[g.edges[k].to].push_back({k, false});
  }
  std::vector<bool> seen(n, false);
  std::queue<std::uint32_t> q;
  for (std::uint32_t v : GaugeVertices(g)) {
    if (v < n && !seen[v]) {
      seen[v] = true;
      q.push(v);
    }
  }
  while (!q.empty()) {
    const std::uint32_t v = q.front();
    q.pop();
    for (const auto& [k, forward] : adjacent[v]) {
      const PoseGraphEdge& e = g.edges[k];
      const std::uint32_t u = forward ? e.to : e.from;
      if (seen[u]) continue;
      seen[u] = true;
      g.poses[u] = forward ? g.poses[v] * e.T_from_to : g.poses[v] * e.T_from_to.inverse();
      q.push(u);
    }
  }
  for (bool s : seen) {
    if (!s) return Error{Errc::kDegenerate, "pose graph: not connected"};
  }
  return Ok();
}

}  // namespace

Status PoseGraphSolverConfig::Validate() const {
  if (max_iterations < 0 || max_iterations > 100000) return Error{Errc::kInvalidConfig, "pose graph: iterations 0..100000"};
  return Ok();
}

Status InitialisePoseGraph(PoseGraph& g, PoseGraphInitialisation method) {
  for (const PoseGraphEdge& e : g.edges) {
    if (e.from >= g.poses.size() || e.to >= g.poses.size()) return Error{Errc::kInvalidArgument, "pose graph: edge to a missing vertex"};
  }
  switch (method) {
    case PoseGraphInitialisation::kAsGiven: return Ok();
    case PoseGraphInitialisation::kSpanningTree: return SpanningTree(g);
    case PoseGraphInitialisation::kChordal: {
      // Connectivity first (the chordal system is singular otherwise).
      PoseGraph copy = g;
      if (Status s = SpanningTree(copy); !s) return s;
      return g.planar ? ChordalInitialise<2>(g) : ChordalInitialise<3>(g);
    }
  }
  return Ok();
}

Expected<PoseGraphReport> OptimizePoseGraph(PoseGraph& g, const PoseGraphSolverConfig& config) {
  if (Status s = config.Validate(); !s) return s.error();
  if (g.poses.empty()) return Error{Errc::kDegenerate, "pose graph: empty"};
  if (Status s = InitialisePoseGraph(g, config.initialisation); !s) return s.error();
  PoseGraphReport report;
  report.initial_objective = SeSyncObjective(g);

  const std::size_t n = g.poses.size();
  ceres::Problem problem;
  std::vector<double> rotation(n * 4, 0.0), translation(n * 3, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    if (g.planar) {
      rotation[i * 4] = std::atan2(g.poses[i].linear()(1, 0), g.poses[i].linear()(0, 0));
    } else {
      const Eigen::Quaterniond q(g.poses[i].linear());
      rotation[i * 4 + 0] = q.x();
      rotation[i * 4 + 1] = q.y();
      rotation[i * 4 + 2] = q.z();
      rotation[i * 4 + 3] = q.w();
    }
    Eigen::Map<Eigen::Vector3d> t_i(&translation[i * 3]);
    t_i = g.poses[i].translation();
  }
  for (const PoseGraphEdge& e : g.edges) {
    double* ri = &rotation[e.from * 4];
    double* rj = &rotation[e.to * 4];
    double* ti = &translation[e.from * 3];
    double* tj = &translation[e.to * 3];
    ceres::CostFunction* cost = nullptr;
    if (config.cost == PoseGraphCost::kChordal) {
      double kappa = 0, tau = 0;
      SeSyncWeights(e, g.planar, kappa, tau);
      if (g.planar) {
        cost = new ceres::AutoDiffCostFunction<ChordalSE2, 6, 1, 2, 1, 2>(new ChordalSE2{
            e.T_from_to.linear().topLeftCorner<2, 2>(), e.T_from_to.translation().head<2>(), std::sqrt(kappa), std::sqrt(tau)});
      } else {
        cost = new ceres::AutoDiffCostFunction<ChordalSE3, 12, 4, 3, 4, 3>(
            new ChordalSE3{e.T_from_to.linear(), e.T_from_to.translation(), std::sqrt(kappa), std::sqrt(tau)});
      }
    } else if (g.planar) {
      Eigen::Matrix3d info;
      const int idx[3] = {0, 1, 5};
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) info(r, c) = e.information(idx[r], idx[c]);
      const Eigen::Matrix3d L = SqrtInformation<3>(info);
      cost = new ceres::AutoDiffCostFunction<GeodesicSE2, 3, 1, 2, 1, 2>(new GeodesicSE2{
          e.T_from_to.translation().x(), e.T_from_to.translation().y(),
          std::atan2(e.T_from_to.linear()(1, 0), e.T_from_to.linear()(0, 0)), L});
    } else {
      const Matrix6d L = SqrtInformation<6>(e.information);
      cost = new ceres::AutoDiffCostFunction<GeodesicSE3, 6, 4, 3, 4, 3>(
          new GeodesicSE3{Eigen::Quaterniond(e.T_from_to.linear()), e.T_from_to.translation(), L});
    }
    problem.AddResidualBlock(cost, nullptr, ri, ti, rj, tj);
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (!problem.HasParameterBlock(&rotation[i * 4])) continue;
    if (!g.planar) problem.SetManifold(&rotation[i * 4], new ceres::EigenQuaternionManifold);
  }
  for (std::uint32_t v : GaugeVertices(g)) {
    if (v < n && problem.HasParameterBlock(&rotation[v * 4])) {
      problem.SetParameterBlockConstant(&rotation[v * 4]);
      problem.SetParameterBlockConstant(&translation[v * 3]);
    }
  }
  ceres::Solver::Summary summary;
  ceres::Solve(SolverOptions(config.max_iterations, config.function_tolerance, config.gradient_tolerance,
                             config.parameter_tolerance),
               &problem, &summary);
  if (!summary.IsSolutionUsable()) return Error{Errc::kNotConverged, "pose graph: the solver failed"};
  for (std::size_t i = 0; i < n; ++i) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    if (g.planar) {
      T.linear() = Eigen::AngleAxisd(rotation[i * 4], Eigen::Vector3d::UnitZ()).toRotationMatrix();
      T.translation() = Eigen::Vector3d(translation[i * 3], translation[i * 3 + 1], 0.0);
    } else {
      T.linear() = Eigen::Quaterniond(rotation[i * 4 + 3], rotation[i * 4], rotation[i * 4 + 1], rotation[i * 4 + 2])
                       .normalized()
                       .toRotationMatrix();
      T.translation() = Eigen::Map<const Eigen::Vector3d>(&translation[i * 3]);
    }
    if (!T.matrix().allFinite()) return Error{Errc::kNotConverged, "pose graph: non-finite solution"};
    g.poses[i] = T;
  }
  report.final_objective = SeSyncObjective(g);
  report.initial_cost = summary.initial_cost;
  report.final_cost = summary.final_cost;
  report.iterations = static_cast<int>(summary.iterations.size());
  report.converged = summary.termination_type == ceres::CONVERGENCE;
  report.solver_seconds = summary.total_time_in_seconds;
  report.solver_report = summary.FullReport();
  return report;
}

}  // namespace msgraphs::core
