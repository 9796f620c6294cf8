// SPDX-License-Identifier: MIT
// Intra-robot loop closure: Scan Context proposes, geometry gates, VGICP verifies.
//
// Every keyframe's Scan Context goes into a bounded database. For a new keyframe, candidates
// are earlier keyframes that are (1) far enough back along the path, (2) near enough in the
// current estimate to be reachable by the odometry's drift since then (1 m plus a fraction of
// the path between them: in a symmetric building an identical room elsewhere is not a
// candidate however alike it looks), and (3) alike by Scan Context. The best few are verified by
// VGICP against the candidate's stored cloud, seeded with the current relative estimate; a
// converged alignment with a low fitness and enough overlap becomes a loop-closure factor
// whose information comes from the alignment's Hessian.
// Sized at Init. Detect allocates: the accepted loop's factor and the solve after it are
// Ceres's; its descriptor search and VGICP verification use buffers sized at Init.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <span>
#include <vector>

#include "msgraphs/base/bounded_vector.hpp"
#include "msgraphs/base/expected.hpp"
#include "msgraphs/core/descriptors/scan_context.hpp"
#include "msgraphs/core/graph/s_graph.hpp"
#include "msgraphs/core/graph/s_graph_solve_job.hpp"
#include "msgraphs/core/perception/kdtree.hpp"
#include "msgraphs/core/registration/gaussian_voxel_map.hpp"
#include "msgraphs/core/registration/vgicp.hpp"

namespace msgraphs {
class SnapshotReader;
class SnapshotWriter;
}  // namespace msgraphs

namespace msgraphs::core {

/// VGICP settings whose fitness counts only points within `max_distance_m` of the target: two
/// clouds never see exactly the same space, and what one sees beyond the other is not
/// misalignment (overlap is judged separately).
inline VgicpConfig VgicpWithFitnessWithin(double max_distance_m) {
  VgicpConfig c;
  c.fitness_max_distance_m = max_distance_m;
  return c;
}

struct LoopClosureConfig {
  ScanContextConfig scan_context{20, 60, 20.0f,
                                 1.0f};  ///< height offset: base above the floor + margin
  float max_scan_context_distance = 0.4f;
  double min_path_gap_m = 10.0;  ///< candidates at least this far back along the path
  double reach_base_m = 1.0;     ///< ...and within reach_base + reach_per_m * path gap
  double reach_per_m = 0.03;
  double max_reach_m = 6.0;
  std::size_t max_verifications = 2;  ///< VGICP runs per keyframe
  double max_fitness_m2 = 0.02;
  double min_overlap = 0.6;  ///< fraction of source points with a target voxel
  double voxel_resolution_m = 0.4;
  double sigma_m = 0.02;  ///< strongest direction's sigma; weaker ones scale from the Hessian
  double min_loop_spacing_m = 2.0;  ///< path between accepted loop closures
  /// After the full solve that follows a loop closure, a loop whose squared whitened residual
  /// is still above this (6 dof, 99.9 %) contradicts the rest of the graph: VGICP found a wrong
  /// minimum that fitness alone could not tell. It is removed and counted.
  double max_chi2_after_solve = 22.46;
  VgicpConfig vgicp = VgicpWithFitnessWithin(1.0);
  Status Validate() const;
};

struct LoopClosureStats {
  std::uint64_t queries = 0, candidates = 0, verified = 0, accepted = 0;
  std::uint64_t rejected_fitness = 0, rejected_overlap = 0, rejected_not_converged = 0,
                cloud_evicted = 0;
  // The newest accepted loop: its keyframes, fitness and how far it moved the estimate.
  std::uint32_t last_from = 0, last_to = 0, last_factor = 0;
  std::uint32_t unused_ = 0;  // no padding: the struct is written whole in a snapshot
  std::uint64_t rejected_after_solve = 0;
  double last_fitness_m2 = 0, last_correction_m = 0;
};

class LoopCloser {
 public:
  /// Its state in a snapshot (LocalMapper::Save / Load): the reader fails on a store of another
  /// size or a value out of range.
  void Save(SnapshotWriter& w) const;
  void Load(SnapshotReader& r);
  /// `max_points`: the largest stored cloud.
  Status Init(std::size_t max_keyframes, std::size_t max_points, const LoopClosureConfig& config);

  /// Stores the keyframe's descriptor; `path_m` is the distance walked when it was taken.
  Status AddKeyframe(std::uint32_t keyframe,
                     std::uint64_t sequence,
                     double path_m,
                     std::span<const Eigen::Vector3f> cloud_base);

  /// Looks for a loop from `keyframe` (already added). `cloud_of(key, sequence)` returns a stored
  /// cloud (empty when evicted); `source`/`source_covariances` are the keyframe's own cloud.
  /// Returns true when a loop-closure factor was added.
  template <typename CloudOf>
  bool Detect(SGraph& graph,
              std::uint32_t keyframe,
              std::span<const Eigen::Vector3f> source,
              std::span<const Eigen::Matrix3f> source_covariances,
              const CloudOf& cloud_of) {
    return DetectImpl(
        graph, keyframe, source, source_covariances,
        [](const void* ctx, std::uint32_t k, std::uint64_t s) {
          return (*static_cast<const CloudOf*>(ctx))(k, s);
        },
        &cloud_of);
  }

  /// Checks the newest loop against the solved graph; removes it (true) when contradicted.
  bool RejectIfContradicted(SGraph& graph);
  /// Checks loop factor `factor` against the solved graph, or against a background full solve
  /// that included it (`job`, before that solve is applied); removes it (true) when contradicted.
  bool RejectIfContradicted(SGraph& graph, std::uint32_t factor, const SGraphSolveJob* job);

  const LoopClosureStats& stats() const { return stats_; }

 private:
  template <class Archive>
  void Io(Archive& ar);
  using CloudFn = std::span<const Eigen::Vector3f> (*)(const void*, std::uint32_t, std::uint64_t);
  bool DetectImpl(SGraph& graph,
                  std::uint32_t keyframe,
                  std::span<const Eigen::Vector3f> source,
                  std::span<const Eigen::Matrix3f> source_covariances,
                  CloudFn cloud_of,
                  const void* ctx);

  struct Entry {
    std::uint64_t sequence = 0;
    double path_m = 0;
    bool valid = false;
  };
  LoopClosureConfig config_;
  std::vector<Entry> entries_;
  // Descriptor cells only (rings x sectors per keyframe): a whole ScanContext carries its
  // maximum-size arrays and keys, 8x more. Candidates are rebuilt from their cells.
  std::vector<float> cells_;
  std::size_t cells_per_keyframe_ = 0;
  ScanContext latest_, candidate_;
  std::uint32_t latest_keyframe_ = 0;
  std::vector<std::pair<float, std::uint32_t>> candidates_;
  BoundedVector<Eigen::Vector3f> target_normals_;
  BoundedVector<Eigen::Matrix3f> target_covariances_;
  KdTree target_tree_;
  GaussianVoxelMap target_map_;
  Vgicp vgicp_;
  double last_loop_path_m_ = -1e300;
  LoopClosureStats stats_;
};

/// Information for a relative-pose factor from an alignment's Gauss-Newton Hessian over
/// [rho; phi]: scaled so that its strongest translational direction has `sigma_m`; the weaker
/// directions keep the Hessian's proportions (a corridor's length stays weak). Falls back to
/// an isotropic sigma when the Hessian is not usable.
Matrix6d InformationFromHessian(const Matrix6d& hessian, double sigma_m);

}  // namespace msgraphs::core
