// SPDX-License-Identifier: MIT
// A pose graph in our own types (the public API never shows Ceres): poses, relative-pose edges
// with information matrices, the g2o text format (EDGE_SE2 / VERTEX_SE2 / EDGE_SE3:QUAT /
// VERTEX_SE3:QUAT / FIX), and the SE-Sync objective used to compare with published optima.
// Parsing works on text already in memory (core does no I/O).
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "msgraphs/base/expected.hpp"

namespace msgraphs::core {

using Matrix6d = Eigen::Matrix<double, 6, 6>;

struct PoseGraphEdge {
  std::uint32_t from = 0, to = 0;
  Eigen::Isometry3d T_from_to = Eigen::Isometry3d::Identity();  ///< measured relative pose
  /// Information over [tx ty tz rx ry rz] (g2o's order). For planar graphs: [x y 0 0 0 theta].
  Matrix6d information = Matrix6d::Identity();
};

struct PoseGraph {
  bool planar = false;  ///< an SE(2) graph (EDGE_SE2): z, roll and pitch stay zero
  std::vector<Eigen::Isometry3d> poses;  ///< T_world_pose, indexed by vertex id
  std::vector<bool> has_initial;         ///< a VERTEX line gave this pose
  std::vector<PoseGraphEdge> edges;
  std::vector<std::uint32_t> fixed;      ///< FIX lines (vertex ids)
};

/// Parses g2o text. kMalformed with the line's reason (e.g. a non-positive-definite information
/// matrix, an unknown tag, an edge to a vertex id beyond 10 million); kUnsupported for mixed 2-D
/// and 3-D graphs. Vertex ids must be dense from 0 (as in the SE-Sync and MRPT files).
Expected<PoseGraph> ParseG2o(std::string_view text, std::string* error_detail = nullptr);

/// Writes g2o text (VERTEX_* with the current poses, EDGE_* with measurements and information).
std::string WriteG2o(const PoseGraph& graph);

/// SE-Sync's objective (Rosen et al., IJRR 2019, eq. 12): sum kappa ||R_j - R_i R_ij||_F^2 +
/// tau ||t_j - t_i - R_i t_ij||^2, with kappa and tau from each edge's information as SE-Sync's
/// reader computes them (2-D: tau = 2 / tr(Omega_tt^-1), kappa = Omega_thetatheta; 3-D:
/// tau = 3 / tr(Omega_tt^-1), kappa = 3 / (2 tr(Omega_RR^-1))). No 1/2 factor.
double SeSyncObjective(const PoseGraph& graph);

/// The weights SeSyncObjective uses for one edge.
void SeSyncWeights(const PoseGraphEdge& edge, bool planar, double& kappa, double& tau);

}  // namespace msgraphs::core
