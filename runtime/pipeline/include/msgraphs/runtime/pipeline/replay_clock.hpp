// SPDX-License-Identifier: MIT
// Maps recorded sensor time to wall time for replay at the recorded pace (times `speed`).
// The first stamp any input thread asks about anchors the mapping, so the LiDAR and the
// odometry recordings stay in step with each other. Thread-safe.
#pragma once

#include <mutex>
#include <optional>

#include "msgraphs/base/time.hpp"

namespace msgraphs::runtime {

class ReplayClock {
 public:
  explicit ReplayClock(double speed) : speed_(speed) {}

  /// When the sample stamped `sensor_s` is due.
  SteadyTime Due(double sensor_s, SteadyTime now) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!anchor_sensor_s_ || sensor_s < *anchor_sensor_s_) {
      // The earliest stamp seen so far anchors; a slightly earlier one from the other input
      // moves the anchor back so that neither input waits for the other's past.
      if (!anchor_sensor_s_)
        anchor_wall_ = now;
      else
        anchor_wall_ =
            anchor_wall_ - Duration::FromSeconds((*anchor_sensor_s_ - sensor_s) / speed_);
      anchor_sensor_s_ = sensor_s;
    }
    return anchor_wall_ + Duration::FromSeconds((sensor_s - *anchor_sensor_s_) / speed_);
  }

 private:
  std::mutex mutex_;
  double speed_;
  std::optional<double> anchor_sensor_s_;
  SteadyTime anchor_wall_;
};

}  // namespace msgraphs::runtime
