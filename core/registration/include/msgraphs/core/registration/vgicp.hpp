// SPDX-License-Identifier: MIT
// Voxelized GICP (Koide et al., ICRA 2021): aligns a source cloud with per-point covariances to
// a target GaussianVoxelMap by minimising sum r^T (C_voxel + R C_src R^T)^-1 r, r = mu - T p,
// with Levenberg-Marquardt on SE(3) (right perturbation T * Exp([rho; phi]), analytic
// Jacobians). Reports the transform, convergence, the fitness the paper's ICP_th = 0.07
// thresholds (mean squared nearest-neighbour distance, as PCL's getFitnessScore) and the final
// Gauss-Newton Hessian (its inverse approximates the pose covariance).
//
// Workspaces are sized at Init; Align allocates nothing.
#pragma once

#include <Eigen/Geometry>
#include <span>
#include <vector>

#include "msgraphs/base/expected.hpp"
#include "msgraphs/core/perception/kdtree.hpp"
#include "msgraphs/core/registration/gaussian_voxel_map.hpp"
#include "msgraphs/core/registration/parallel.hpp"

namespace msgraphs::core {

struct VgicpConfig {
  int max_iterations = 64;
  double rotation_eps_rad = 2e-3;     ///< converged when the update rotates less
  double translation_eps_m = 5e-4;    ///< and translates less
  /// LM damping starts at this factor times the largest diagonal entry of the Hessian and is
  /// scaled by 10 on a rejected step (fast_gicp's scheme).
  double initial_lambda_factor = 1e-9;
  int max_lm_retries = 10;
  /// 1: only the voxel holding the point (fast_gicp DIRECT1); 7: it and its face neighbours.
  int neighbour_voxels = 1;
  /// Points whose nearest target point is farther are left out of the fitness (PCL default: all).
  double fitness_max_distance_m = 1e9;

  Status Validate() const;
};

/// A prior on the transform (another sensor's measurement of it, e.g. encoder odometry), with
/// its information in the registration's own units (over [rho; phi], right perturbation):
/// directions the clouds constrain weakly (along a corridor) then stay where the prior puts
/// them instead of sliding on noise; directions they constrain strongly follow the clouds. The
/// result's `hessian` is the clouds' alone.
struct VgicpPrior {
  Eigen::Isometry3d T_target_source = Eigen::Isometry3d::Identity();
  Eigen::Matrix<double, 6, 6> information = Eigen::Matrix<double, 6, 6>::Zero();
  /// > 0: `information` is in metric units, and the clouds' Hessian (whose scale is the
  /// covariances', not the sensor's noise) counts as information whose strongest translational
  /// direction has this sigma, as the caller will report it (InformationFromHessian); the
  /// prior is converted at the first linearisation. 0: `information` is in the Hessian's units.
  double clouds_sigma_m = 0;
};

struct VgicpResult {
  Eigen::Isometry3d T_target_source = Eigen::Isometry3d::Identity();
  bool converged = false;
  int iterations = 0;
  double final_cost = 0.0;
  std::size_t correspondences = 0;  ///< source points with a target voxel at the end
  double fitness = 0.0;             ///< mean squared NN distance to target points, m^2
  std::size_t fitness_points = 0;
  Eigen::Matrix<double, 6, 6> hessian = Eigen::Matrix<double, 6, 6>::Zero();  ///< over [rho; phi]
};

class Vgicp {
 public:
  /// Sizes the workspaces: correspondences for up to `max_source_points` points and per-chunk
  /// accumulators for up to `max_chunks` parallel chunks.
  void Init(std::size_t max_source_points, std::size_t max_chunks = 16);

  /// `target_points`/`target_tree` serve the fitness score; `target_map` the alignment.
  /// kDegenerate for fewer than 10 source points or no correspondences at the start;
  /// kInvalidArgument for mismatched sizes or a non-rigid guess; kNotConverged is not an error
  /// (see result.converged). Never returns a NaN transform.
  Expected<VgicpResult> Align(std::span<const Eigen::Vector3f> source_points,
                              std::span<const Eigen::Matrix3f> source_covariances, const GaussianVoxelMap& target_map,
                              std::span<const Eigen::Vector3f> target_points, const KdTree& target_tree,
                              const Eigen::Isometry3d& initial_guess, const VgicpConfig& config,
                              const ParallelExecutor* executor = nullptr, const VgicpPrior* prior = nullptr);

 private:
  struct Accumulator {
    Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> b = Eigen::Matrix<double, 6, 1>::Zero();
    double cost = 0.0;
    std::size_t count = 0;
  };
  struct Job;
  static void LinearizeChunk(void* job, std::size_t chunk);
  static void FitnessChunk(void* job, std::size_t chunk);

  std::vector<Accumulator> chunks_;
  // The voxels each source point was matched to at the last linearisation (up to 7 per point).
  // Trial steps are scored against these fixed correspondences so that costs compare fairly.
  std::vector<const GaussianVoxel*> correspondences_;
};

}  // namespace msgraphs::core
