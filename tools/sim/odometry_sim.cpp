// SPDX-License-Identifier: MIT
#include "odometry_sim.hpp"

#include <cmath>
#include <numbers>

#include "msgraphs/drivers/can_odometry/candump_file.hpp"
#include "msgraphs/drivers/can_odometry/odometry_frames.hpp"
#include "random.hpp"

namespace msgraphs::sim {

bool RenderOdometry(const Trajectory& trajectory, const OdometrySimConfig& config, const RobotClocks& clocks,
                    std::uint64_t seed, int robot, const std::string& candump_path, OdometrySimStats& stats,
                    std::string& error) {
  namespace can = msgraphs::drivers::can_odometry;
  auto writer = can::CandumpFileWriter::Create(candump_path.c_str(), can::CandumpPrecision::kMicroseconds);
  if (!writer) {
    error = candump_path + ": " + writer.error().detail;
    return false;
  }
  Random rng = Random::Stream(seed, 0x6F646F6D + static_cast<std::uint64_t>(robot));  // "odom"
  const double sign_s = rng.Chance(0.5) ? 1.0 : -1.0;
  stats.scale_error = sign_s * rng.Uniform(config.scale_error_min, config.scale_error_max);
  const double sign_y = rng.Chance(0.5) ? 1.0 : -1.0;
  stats.yaw_drift_rad_per_m =
      sign_y * rng.Uniform(0.7, 1.3) * config.yaw_drift_deg_per_10m * std::numbers::pi / 180.0 / 10.0;

  const double dt = 1.0 / config.rate_hz;
  const auto samples = static_cast<std::int64_t>(std::floor(trajectory.duration_s() * config.rate_hz));
  PlanarPose previous = trajectory.Planar(0.0);
  for (std::int64_t k = 1; k <= samples; ++k) {
    const double t = static_cast<double>(k) * dt;
    const PlanarPose now = trajectory.Planar(t);
    // True motion in the previous body frame.
    const double c = std::cos(previous.yaw), s = std::sin(previous.yaw);
    const double wx = now.x - previous.x, wy = now.y - previous.y;
    const double dx = c * wx + s * wy, dy = -s * wx + c * wy;
    const double dyaw = std::remainder(now.yaw - previous.yaw, 2 * std::numbers::pi);
    const double ds = std::hypot(dx, dy);
    stats.path_length_m += ds;
    previous = now;

    can::OdomSampleValues v;
    v.sequence = static_cast<std::uint8_t>(k & 0xFF);
    v.sample_time_us = clocks.BridgeUs(t);
    v.status = can::kStatusValid;
    v.dx_m = dx * (1.0 + stats.scale_error) + rng.Normal(config.noise_xy_m);
    v.dy_m = dy * (1.0 + stats.scale_error) + rng.Normal(config.noise_xy_m);
    v.dyaw_rad = dyaw + stats.yaw_drift_rad_per_m * ds + rng.Normal(config.noise_yaw_rad);
    v.dz_m = rng.Normal(0.0002);
    v.droll_rad = rng.Normal(0.0001);
    v.dpitch_rad = rng.Normal(0.0001);
    if (rng.Chance(config.drop_probability)) {
      ++stats.dropped;
      continue;
    }
    // The bridge sends the three frames back to back (~230 us each at 500 kbit/s); the host
    // stamps them on arrival.
    const double latency = 300e-6 + std::fabs(rng.Normal(100e-6));
    const auto frames = can::EncodeOdomSample(v);
    for (std::size_t f = 0; f < frames.size(); ++f) {
      const UnixTime stamp = clocks.Host(t + latency + static_cast<double>(f) * 230e-6);
      if (Status st = writer->Write(stamp, config.interface, frames[f]); !st) {
        error = candump_path + ": " + st.error().detail;
        return false;
      }
    }
    ++stats.samples;
  }
  if (Status st = writer->Close(); !st) {
    error = candump_path + ": " + st.error().detail;
    return false;
  }
  return true;
}

}  // namespace msgraphs::sim
