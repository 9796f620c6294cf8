// SPDX-License-Identifier: MIT
#include "walker.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace msgraphs::sim {

Walker::Walker(Trajectory& trajectory, const WalkerLimits& limits, double end_s)
    : trajectory_(trajectory), limits_(limits), end_s_(end_s) {
  if (!trajectory_.samples().empty()) pose_ = trajectory_.samples().back();
}

void Walker::Step(double turn_rps) {
  const double dt = trajectory_.dt_s();
  pose_.yaw = std::remainder(pose_.yaw + turn_rps * dt, 2 * std::numbers::pi);
  pose_.x += speed_mps_ * std::cos(pose_.yaw) * dt;
  pose_.y += speed_mps_ * std::sin(pose_.yaw) * dt;
  trajectory_.Append(pose_);
}

bool Walker::Follow(const std::vector<Eigen::Vector2d>& path) {
  const double dt = trajectory_.dt_s();
  // Path length left after each point: the robot slows down in time to stop at the end, not
  // only on the last segment (which can be shorter than a full stop needs).
  std::vector<double> left_m(path.size(), 0.0);
  for (std::size_t i = path.size() - 1; i-- > 0;)
    left_m[i] = left_m[i + 1] + (path[i + 1] - path[i]).norm();
  std::size_t target = 1;
  while (target < path.size()) {
    if (done()) return false;
    const Eigen::Vector2d to = path[target] - position();
    const double dist = to.norm();
    const bool last = target + 1 == path.size();
    if (dist < (last ? 0.05 : 0.25)) {
      ++target;
      continue;
    }
    const double heading_error =
        std::remainder(std::atan2(to.y(), to.x()) - pose_.yaw, 2 * std::numbers::pi);
    double wanted_speed = 0.0;
    if (std::fabs(heading_error) < 0.6) {
      wanted_speed = limits_.max_speed_mps * std::cos(heading_error);
      wanted_speed =
          std::min(wanted_speed, std::sqrt(2 * limits_.max_accel_mps2 * (dist + left_m[target])));
    }
    speed_mps_ += std::clamp(wanted_speed - speed_mps_, -limits_.max_accel_mps2 * dt,
                             limits_.max_accel_mps2 * dt);
    Step(std::clamp(2.0 * heading_error, -limits_.max_turn_rate_rps, limits_.max_turn_rate_rps));
  }
  // Come to a stop where the path ends (the last approach already slowed down).
  while (speed_mps_ > 0.0 && !done()) {
    speed_mps_ = std::max(0.0, speed_mps_ - limits_.max_accel_mps2 * dt);
    Step(0.0);
  }
  return !done();
}

bool Walker::TurnTo(double yaw_rad) {
  while (!done()) {
    const double error = std::remainder(yaw_rad - pose_.yaw, 2 * std::numbers::pi);
    if (std::fabs(error) < 0.01) return true;
    speed_mps_ = 0.0;
    Step(std::clamp(2.0 * error, -limits_.max_turn_rate_rps, limits_.max_turn_rate_rps));
  }
  return false;
}

bool Walker::Hold(double seconds) {
  const double until = now_s() + seconds;
  speed_mps_ = 0.0;
  while (!done() && now_s() < until - 1e-9) Step(0.0);
  return !done();
}

}  // namespace msgraphs::sim
