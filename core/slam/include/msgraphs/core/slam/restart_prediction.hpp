// SPDX-License-Identifier: MIT
// Where a robot may be when its restarted node first sees a scan: the motion it had when the
// journal stopped (its last half second of odometry), kept on through the downtime. The node
// builds its relocalisation search from it (and falls back on it when nothing aligns);
// msgraphs_relocalise_eval builds the same search, so that what it measures is what the node
// does.
#pragma once

#include <Eigen/Geometry>

#include "msgraphs/core/slam/local_mapper.hpp"
#include "msgraphs/core/slam/odometry_buffer.hpp"

namespace msgraphs::core {

class RestartPrediction {
 public:
  /// `odometry` holds the journaled odometry up to `last_stamp_s`, where it gave `T_odom_last`.
  RestartPrediction(const OdometryBuffer& odometry, const Eigen::Isometry3d& T_odom_last,
                    double last_stamp_s);

  /// The last half second's motion kept on for `seconds` (at most 30 s): its translation in the
  /// last pose's own x-y plane and its turn about that pose's z axis only (the base's rocking
  /// is not extrapolated into a climb or a roll).
  Eigen::Isometry3d KeptOn(double seconds) const;

  /// The search for a scan ending at `scan_end_s`: from the last pose along the kept motion for
  /// 1.5 times the time since (the robot may have slowed or stopped), and failing that anywhere
  /// within reach at `max_speed_mps`.
  RelocaliseSearch Search(double scan_end_s, double max_speed_mps) const;

  double last_stamp_s() const { return last_stamp_s_; }
  const Eigen::Isometry3d& T_odom_last() const { return T_odom_last_; }

 private:
  Eigen::Isometry3d T_odom_last_;
  Eigen::Isometry3d step_ = Eigen::Isometry3d::Identity();  ///< per half second
  double last_stamp_s_;
};

}  // namespace msgraphs::core
