// SPDX-License-Identifier: MIT
// Pose-graph optimisation on Ceres (a private dependency: nothing here shows it).
//
// Two costs:
// - kChordal: SE-Sync's objective itself (Frobenius rotation residuals), whose minimum the
//   published SE-Sync optima report;
// - kGeodesic: the g2o/MRPT chi^2: the relative-pose error (x, y, theta in 2-D; translation and
//   rotation vector in 3-D) weighted by the edge's information.
// Initialisation: chordal relaxation (Carlone et al. 2015; SE-Sync's default): rotations from a
// linear least-squares problem over unconstrained matrices, projected onto SO(d), then
// translations from another linear problem; or the poses as given, or composed along a spanning
// tree for graphs without vertices. The first vertex (or every FIX vertex) fixes the gauge.
#pragma once

#include <string>

#include "msgraphs/base/expected.hpp"
#include "msgraphs/core/graph/pose_graph.hpp"

namespace msgraphs::core {

enum class PoseGraphCost : std::uint8_t { kChordal, kGeodesic };
enum class PoseGraphInitialisation : std::uint8_t { kAsGiven, kSpanningTree, kChordal };

struct PoseGraphSolverConfig {
  PoseGraphCost cost = PoseGraphCost::kChordal;
  PoseGraphInitialisation initialisation = PoseGraphInitialisation::kChordal;
  int max_iterations = 200;
  double function_tolerance = 1e-9;   // relative cost change: far below the 1e-3 goal
  double gradient_tolerance = 1e-10;
  double parameter_tolerance = 1e-10;
  Status Validate() const;
};

struct PoseGraphReport {
  double initial_objective = 0;  ///< SE-Sync objective after initialisation
  double final_objective = 0;    ///< SE-Sync objective at the solution
  double initial_cost = 0;       ///< the optimised cost (Ceres' 1/2 sum r^2) before and after
  double final_cost = 0;
  int iterations = 0;
  bool converged = false;
  double solver_seconds = 0;     ///< as Ceres measured it
  std::string solver_report;     ///< the solver's own full report, for diagnosis
};

/// Initialises (per config) and optimises `graph.poses` in place. kInvalidArgument for edges to
/// missing vertices; kDegenerate for a graph that is not connected; kNotConverged is not an
/// error (report.converged).
Expected<PoseGraphReport> OptimizePoseGraph(PoseGraph& graph, const PoseGraphSolverConfig& config);

/// Only the initialisation step (for tests and tools).
Status InitialisePoseGraph(PoseGraph& graph, PoseGraphInitialisation method);

}  // namespace msgraphs::core
