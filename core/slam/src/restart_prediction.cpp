// SPDX-License-Identifier: MIT
#include "msgraphs/core/slam/restart_prediction.hpp"

#include <algorithm>
#include <cmath>

namespace msgraphs::core {

RestartPrediction::RestartPrediction(const OdometryBuffer& odometry,
                                     const Eigen::Isometry3d& T_odom_last, double last_stamp_s)
    : T_odom_last_(T_odom_last), last_stamp_s_(last_stamp_s) {
  if (auto before = odometry.At(last_stamp_s - 0.5)) step_ = before->T_odom_base.inverse() * T_odom_last;
}

Eigen::Isometry3d RestartPrediction::KeptOn(double seconds) const {
  const double k = std::clamp(seconds / 0.5, 0.0, 60.0);
  const double yaw = std::atan2(step_.linear()(1, 0), step_.linear()(0, 0));
  Eigen::Isometry3d ahead = Eigen::Isometry3d::Identity();
  ahead.linear() = Eigen::AngleAxisd(k * yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  ahead.translation() << k * step_.translation().x(), k * step_.translation().y(), 0;
  return T_odom_last_ * ahead;
}

RelocaliseSearch RestartPrediction::Search(double scan_end_s, double max_speed_mps) const {
  RelocaliseSearch search;
  search.T_odom_from = T_odom_last_;
  const double since_s = std::max(scan_end_s - last_stamp_s_, 0.0);
  search.T_odom_to = KeptOn(1.5 * since_s);
  search.reach_m = max_speed_mps * since_s;
  return search;
}

}  // namespace msgraphs::core
