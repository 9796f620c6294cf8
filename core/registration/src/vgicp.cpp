// SPDX-License-Identifier: MIT
#include "msgraphs/core/registration/vgicp.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <cmath>

#include "msgraphs/core/geometry/se3.hpp"

namespace msgraphs::core {
namespace {

Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d S;
  S << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return S;
}

constexpr int kOffsets7[7][3] = {{0, 0, 0}, {1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};

}  // namespace

Status VgicpConfig::Validate() const {
  if (max_iterations < 1 || max_iterations > 1000) return Error{Errc::kInvalidConfig, "vgicp: iterations must be 1..1000"};
  if (neighbour_voxels != 1 && neighbour_voxels != 7) return Error{Errc::kInvalidConfig, "vgicp: neighbour voxels must be 1 or 7"};
  if (!(rotation_eps_rad > 0) || !(translation_eps_m > 0) || !(initial_lambda_factor >= 0)) {
    return Error{Errc::kInvalidConfig, "vgicp: epsilons must be > 0 and lambda >= 0"};
  }
  return Ok();
}

struct Vgicp::Job {
  std::span<const Eigen::Vector3f> src;
  std::span<const Eigen::Matrix3f> src_cov;
  const GaussianVoxelMap* map;
  std::span<const Eigen::Vector3f> target_points;
  const KdTree* tree;
  const VgicpConfig* config;
  Eigen::Isometry3d T;
  bool with_jacobians;  // linearise: find correspondences, accumulate H and b
  std::size_t chunks;
  std::vector<Accumulator>* out;
  std::vector<const GaussianVoxel*>* matches;
};

void Vgicp::LinearizeChunk(void* context, std::size_t chunk) {
  Job& job = *static_cast<Job*>(context);
  Accumulator& acc = (*job.out)[chunk];
  acc.H.setZero();
  acc.b.setZero();
  acc.cost = 0;
  acc.count = 0;
  const std::size_t n = job.src.size();
  const std::size_t begin = n * chunk / job.chunks, end = n * (chunk + 1) / job.chunks;
  const Eigen::Matrix3d R = job.T.linear();
  const Eigen::Vector3d t = job.T.translation();
  const int offsets = job.config->neighbour_voxels;
  for (std::size_t i = begin; i < end; ++i) {
    const Eigen::Vector3d p = job.src[i].cast<double>();
    const Eigen::Vector3d Tp = R * p + t;
    const Eigen::Matrix3d RCRt = R * job.src_cov[i].cast<double>() * R.transpose();
    const GaussianVoxel** matched = job.matches->data() + i * 7;
    for (int o = 0; o < offsets; ++o) {
      const GaussianVoxel* v = nullptr;
      if (job.with_jacobians) {
        v = job.map->Lookup(Tp, kOffsets7[o][0], kOffsets7[o][1], kOffsets7[o][2]);
        matched[o] = v;
      } else {
        v = matched[o];  // scored against the correspondences of the last linearisation
      }
      if (v == nullptr) continue;
      const Eigen::Matrix3d M = (v->covariance + RCRt).inverse();
      const Eigen::Vector3d r = v->mean - Tp;
      acc.cost += r.dot(M * r);
      ++acc.count;
      if (!job.with_jacobians) continue;
      // r(T Exp([rho; phi])) ~ r + R [p]x phi - R rho.
      Eigen::Matrix<double, 3, 6> J;
      J.leftCols<3>() = -R;
      J.rightCols<3>() = R * Skew(p);
      const Eigen::Matrix<double, 6, 3> JtM = J.transpose() * M;
      acc.H += JtM * J;
      acc.b += JtM * r;
    }
  }
}

void Vgicp::FitnessChunk(void* context, std::size_t chunk) {
  Job& job = *static_cast<Job*>(context);
  Accumulator& acc = (*job.out)[chunk];
  acc.cost = 0;
  acc.count = 0;
  const std::size_t n = job.src.size();
  const std::size_t begin = n * chunk / job.chunks, end = n * (chunk + 1) / job.chunks;
  const auto max_d2 = static_cast<float>(std::min(1e18, job.config->fitness_max_distance_m * job.config->fitness_max_distance_m));
  for (std::size_t i = begin; i < end; ++i) {
    const Eigen::Vector3f q = (job.T * job.src[i].cast<double>()).cast<float>();
    std::uint32_t idx = 0;
    float d2 = 0;
    if (job.tree->Nearest(q, idx, d2, max_d2)) {
      acc.cost += static_cast<double>(d2);
      ++acc.count;
    }
  }
}

void Vgicp::Init(std::size_t max_source_points, std::size_t max_chunks) {
  chunks_.assign(std::max<std::size_t>(1, max_chunks), Accumulator{});
  correspondences_.assign(7 * max_source_points, nullptr);
}

Expected<VgicpResult> Vgicp::Align(std::span<const Eigen::Vector3f> source_points,
                                   std::span<const Eigen::Matrix3f> source_covariances,
                                   const GaussianVoxelMap& target_map, std::span<const Eigen::Vector3f> target_points,
                                   const KdTree& target_tree, const Eigen::Isometry3d& initial_guess,
                                   const VgicpConfig& config, const ParallelExecutor* executor,
                                   const VgicpPrior* prior) {
  if (Status s = config.Validate(); !s) return s.error();
  if (chunks_.empty()) return Error{Errc::kInvalidArgument, "vgicp: Init was not called"};
  if (source_points.size() != source_covariances.size()) return Error{Errc::kInvalidArgument, "vgicp: one covariance per source point"};
  if (7 * source_points.size() > correspondences_.size()) {
    return Error{Errc::kCapacityExceeded, "vgicp: more source points than Init allowed"};
  }
  if (target_tree.size() != target_points.size()) return Error{Errc::kInvalidArgument, "vgicp: the tree must index the target points"};
  if (!IsValidRigidTransform(initial_guess, 1e-4)) return Error{Errc::kInvalidArgument, "vgicp: the initial guess is not a rigid transform"};
  if (source_points.size() < 10 || target_map.voxels() == 0 || target_points.empty()) {
    return Error{Errc::kDegenerate, "vgicp: too few points to align"};
  }
  for (std::size_t i = 0; i < source_points.size(); ++i) {
    if (!source_points[i].allFinite() || !source_covariances[i].allFinite()) {
      return Error{Errc::kInvalidArgument, "vgicp: non-finite source point or covariance"};
    }
  }

  Job job{source_points, source_covariances, &target_map, target_points, &target_tree, &config,
          initial_guess, true, 1, &chunks_, &correspondences_};
  job.chunks = executor != nullptr ? std::min(chunks_.size(), std::max<std::size_t>(1, executor->concurrency())) : 1;
  auto run = [&](void (*fn)(void*, std::size_t)) {
    if (executor != nullptr && job.chunks > 1) {
      executor->Run(job.chunks, fn, &job);
    } else {
      for (std::size_t c = 0; c < job.chunks; ++c) fn(&job, c);
    }
    Accumulator sum;
    for (std::size_t c = 0; c < job.chunks; ++c) {
      sum.H += chunks_[c].H;
      sum.b += chunks_[c].b;
      sum.cost += chunks_[c].cost;
      sum.count += chunks_[c].count;
    }
    return sum;
  };
  if (prior != nullptr && (!IsValidRigidTransform(prior->T_target_source, 1e-4) || !prior->information.allFinite())) {
    return Error{Errc::kInvalidArgument, "vgicp: the prior is not a rigid transform or its information is not finite"};
  }
  // The prior's residual e = Log(T_prior^-1 T); for T * Exp(delta), de/d(delta) is about the
  // identity near the prior (its right Jacobian), which is where a prior is any use.
  Eigen::Isometry3d T_prior_inv = Eigen::Isometry3d::Identity();
  if (prior != nullptr) T_prior_inv = prior->T_target_source.inverse();
  Eigen::Matrix<double, 6, 6> prior_information = Eigen::Matrix<double, 6, 6>::Zero();
  auto add_prior = [&](const Eigen::Isometry3d& T, Accumulator& acc, bool jacobians) {
    if (prior == nullptr) return;
    const Vector6d e = Se3Log(T_prior_inv * T);
    acc.cost += e.dot(prior_information * e);
    if (jacobians) {
      acc.H += prior_information;
      acc.b += prior_information * e;
    }
  };
  Eigen::Matrix<double, 6, 6> clouds_hessian = Eigen::Matrix<double, 6, 6>::Zero();
  auto evaluate = [&](const Eigen::Isometry3d& T, bool jacobians) {
    job.T = T;
    job.with_jacobians = jacobians;
    Accumulator acc = run(&Vgicp::LinearizeChunk);
    if (jacobians) clouds_hessian = acc.H;
    add_prior(T, acc, jacobians);
    return acc;
  };

  VgicpResult result;
  Eigen::Isometry3d T = initial_guess;
  Accumulator lin = evaluate(T, true);
  if (lin.count < 10) return Error{Errc::kDegenerate, "vgicp: fewer than 10 correspondences at the initial guess"};
  if (prior != nullptr) {
    prior_information = prior->information;
    if (prior->clouds_sigma_m > 0) {
      // Metric information -> Hessian units: the Hessian H counts as H / (sigma^2 lambda_max).
      const Eigen::Matrix3d Htt = 0.5 * (clouds_hessian.topLeftCorner<3, 3>() +
                                         clouds_hessian.topLeftCorner<3, 3>().transpose());
      const double strongest = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(Htt).eigenvalues().maxCoeff();
      prior_information *= strongest > 0 ? prior->clouds_sigma_m * prior->clouds_sigma_m * strongest : 0.0;
    }
    add_prior(T, lin, true);  // the first linearisation, now with the prior
  }
  double lambda = config.initial_lambda_factor * lin.H.diagonal().maxCoeff();
  for (int iteration = 0; iteration < config.max_iterations; ++iteration) {
    result.iterations = iteration + 1;
    bool accepted = false;
    Vector6d delta = Vector6d::Zero();
    for (int retry = 0; retry <= config.max_lm_retries; ++retry) {
      const Eigen::Matrix<double, 6, 6> A = lin.H + lambda * Eigen::Matrix<double, 6, 6>::Identity();
      // The cost decreases along -(H + lambda I)^-1 b for r = mu - T p and J = dr/dxi.
      delta = -A.ldlt().solve(lin.b);
      if (!delta.allFinite()) break;
      const Eigen::Isometry3d candidate = T * Se3Exp(delta);
      const Accumulator trial = evaluate(candidate, false);  // same correspondences
      if (trial.cost <= lin.cost) {
        T = candidate;
        lambda /= 10.0;
        accepted = true;
        break;
      }
      lambda = lambda > 0.0 ? lambda * 10.0 : 1e-6;
    }
    if (!accepted) {
      // No step lowers the cost, not even a heavily damped one: a minimum, to the precision
      // the damped step shows (fast_gicp's criterion).
      result.converged = delta.allFinite() && delta.tail<3>().norm() < config.rotation_eps_rad &&
                         delta.head<3>().norm() < config.translation_eps_m;
      break;
    }
    const bool small = delta.tail<3>().norm() < config.rotation_eps_rad && delta.head<3>().norm() < config.translation_eps_m;
    lin = evaluate(T, true);
    if (lin.count < 10) return Error{Errc::kDegenerate, "vgicp: the alignment left the target"};
    if (small) {
      result.converged = true;
      break;
    }
  }
  if (!T.matrix().allFinite()) return Error{Errc::kNotConverged, "vgicp: the solution diverged"};
  result.T_target_source = T;
  result.final_cost = lin.cost;
  result.correspondences = lin.count;
  result.hessian = clouds_hessian;
  job.T = T;
  const Accumulator fit = run(&Vgicp::FitnessChunk);
  result.fitness_points = fit.count;
  result.fitness = fit.count > 0 ? fit.cost / static_cast<double>(fit.count) : 0.0;
  return result;
}

}  // namespace msgraphs::core
