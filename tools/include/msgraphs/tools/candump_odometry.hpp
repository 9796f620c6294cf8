// SPDX-License-Identifier: MIT
// A recording's encoder odometry (candump file -> CAN decoder -> integrated T_odom_base), read
// forward on demand by the host tools that replay a recording in lock-step.
#pragma once

#include <Eigen/Geometry>
#include <memory>
#include <utility>

#include "msgraphs/drivers/can_odometry/candump_file.hpp"
#include "msgraphs/drivers/can_odometry/odometry_stream.hpp"

namespace msgraphs::tools {

class CandumpOdometry {
 public:
  /// nullptr when the file cannot be opened.
  static std::unique_ptr<CandumpOdometry> Open(const char* path) {
    auto reader = drivers::can_odometry::CandumpFileReader::Open(path);
    auto stream = drivers::can_odometry::OdometryStream::Create({});
    if (!reader || !stream) return nullptr;
    return std::unique_ptr<CandumpOdometry>(new CandumpOdometry(std::move(*reader), std::move(*stream)));
  }

  /// Calls sink(stamp_s, T_odom_base) for each pose, once, until one at or after `t_s` (or the
  /// file's end).
  template <typename Sink>
  void Until(double t_s, Sink&& sink) {
    while (!done_ && newest_s_ < t_s) {
      auto next = reader_.Next(line_);
      if (!next || !*next) {
        done_ = true;
        break;
      }
      if (!stream_.Add(line_.frame, line_.stamp)) continue;
      const auto& p = stream_.pose();
      const auto& P = p.T_odom_base;
      Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
      T.linear() = Eigen::Quaterniond(P.qw, P.qx, P.qy, P.qz).normalized().toRotationMatrix();
      T.translation() = Eigen::Vector3d(P.x_m, P.y_m, P.z_m);
      newest_s_ = p.stamp.seconds_since_epoch();
      sink(newest_s_, T);
    }
  }

  /// Reads no more (the encoders are not used).
  void Stop() { done_ = true; }

 private:
  CandumpOdometry(drivers::can_odometry::CandumpFileReader reader,
                  drivers::can_odometry::OdometryStream stream)
      : reader_(std::move(reader)), stream_(std::move(stream)) {}

  drivers::can_odometry::CandumpFileReader reader_;
  drivers::can_odometry::OdometryStream stream_;
  drivers::can_odometry::CandumpLine line_;
  double newest_s_ = -1e300;
  bool done_ = false;
};

}  // namespace msgraphs::tools
