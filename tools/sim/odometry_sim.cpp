// SPDX-License-Identifier: MIT
#include "odometry_sim.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "msgraphs/drivers/can_odometry/candump_file.hpp"
#include "msgraphs/drivers/can_odometry/odometry_frames.hpp"
#include "random.hpp"

namespace msgraphs::sim {
namespace {

// Draws the next slip event (everything but its start).
SlipEvent DrawSlip(const SlipConfig& c, Random& rng) {
  SlipEvent e;
  e.duration_s = rng.Uniform(c.duration_min_s, c.duration_max_s);
  const double total = c.weight_scale + c.weight_yaw + c.weight_both;
  const double u = rng.Uniform(0, total > 0 ? total : 1.0);
  const bool scale = u < c.weight_scale || u >= c.weight_scale + c.weight_yaw;
  const bool yaw = u >= c.weight_scale;
  e.kind = scale && yaw ? "scale+yaw" : scale ? "scale" : "yaw";
  // Draw both so that the stream does not depend on the kind.
  const double factor = rng.Uniform(c.scale_min, c.scale_max);
  const double yaw_rad = rng.Uniform(-c.yaw_max_deg, c.yaw_max_deg) * std::numbers::pi / 180.0;
  e.scale = scale ? factor : 1.0;
  e.yaw_rad = yaw ? yaw_rad : 0.0;
  return e;
}

}  // namespace

bool RenderOdometry(const Trajectory& trajectory,
                    const OdometrySimConfig& config,
                    const RobotClocks& clocks,
                    std::uint64_t seed,
                    int robot,
                    const std::string& candump_path,
                    OdometrySimStats& stats,
                    std::string& error) {
  namespace can = msgraphs::drivers::can_odometry;
  auto writer =
      can::CandumpFileWriter::Create(candump_path.c_str(), can::CandumpPrecision::kMicroseconds);
  if (!writer) {
    error = candump_path + ": " + writer.error().detail;
    return false;
  }
  Random rng = Random::Stream(seed, 0x6F646F6D + static_cast<std::uint64_t>(robot));  // "odom"
  const double sign_s = rng.Chance(0.5) ? 1.0 : -1.0;
  stats.scale_error = sign_s * rng.Uniform(config.scale_error_min, config.scale_error_max);
  const double sign_y = rng.Chance(0.5) ? 1.0 : -1.0;
  stats.yaw_drift_rad_per_m = sign_y * rng.Uniform(0.7, 1.3) * config.yaw_drift_deg_per_10m *
                              std::numbers::pi / 180.0 / 10.0;
  // Slips have their own stream: switching them off leaves every other error as it was.
  Random slip_rng = Random::Stream(seed, 0x736C6970, static_cast<std::uint64_t>(robot));  // "slip"
  const SlipConfig& sc = config.slip;
  stats.slip_per_100m = sc.enabled ? slip_rng.Uniform(sc.per_100m_min, sc.per_100m_max) : 0.0;
  stats.slips.clear();
  auto next_gap_m = [&] {
    return -std::log(1.0 - slip_rng.Uniform()) * 100.0 / stats.slip_per_100m;
  };
  double next_slip_at_m =
      stats.slip_per_100m > 0 ? next_gap_m() : std::numeric_limits<double>::infinity();
  std::int64_t slip_last_k = -1;  // the event covers samples (first .. slip_last_k)

  const double dt = 1.0 / config.rate_hz;
  const auto samples =
      static_cast<std::int64_t>(std::floor(trajectory.duration_s() * config.rate_hz));
  Eigen::Isometry3d previous = trajectory.Pose(0.0);
  for (std::int64_t k = 1; k <= samples; ++k) {
    const double t = static_cast<double>(k) * dt;
    const Eigen::Isometry3d now = trajectory.Pose(t);
    // True motion in the previous body frame, as the DBC defines it: R = Rz(yaw) Ry(pitch)
    // Rx(roll).
    const Eigen::Isometry3d delta = previous.inverse() * now;
    previous = now;
    const Eigen::Matrix3d& R = delta.linear();
    const double dx = delta.translation().x(), dy = delta.translation().y(),
                 dz = delta.translation().z();
    const double dyaw = std::atan2(R(1, 0), R(0, 0));
    const double dpitch = std::asin(std::clamp(-R(2, 0), -1.0, 1.0));
    const double droll = std::atan2(R(2, 1), R(2, 2));
    const double ds = std::hypot(dx, dy);
    stats.path_length_m += ds;

    // A slip starts with the sample in which the walked distance passes the next event's mark
    // and lasts whole samples, so the listed duration and heading error are exactly reported.
    if (k > slip_last_k && stats.path_length_m >= next_slip_at_m) {
      SlipEvent slip = DrawSlip(sc, slip_rng);
      const auto n = std::max<std::int64_t>(1, std::llround(slip.duration_s / dt));
      slip.duration_s = static_cast<double>(n) * dt;
      slip.start_s = trajectory.start_s() + t - dt;
      slip_last_k = k + n - 1;
      stats.slips.push_back(slip);
    }
    double slip_scale = 1.0, slip_yaw_rad = 0.0;
    if (k <= slip_last_k) {
      SlipEvent& e = stats.slips.back();
      slip_scale = e.scale;
      slip_yaw_rad = e.yaw_rad * dt / e.duration_s;
      e.true_m += ds;
      if (k == slip_last_k) next_slip_at_m = stats.path_length_m + next_gap_m();
    }

    can::OdomSampleValues v;
    v.sequence = static_cast<std::uint8_t>(k & 0xFF);
    v.sample_time_us = clocks.BridgeUs(t);
    v.status = can::kStatusValid;
    v.dx_m = dx * (1.0 + stats.scale_error) * slip_scale + rng.Normal(config.noise_xy_m);
    v.dy_m = dy * (1.0 + stats.scale_error) * slip_scale + rng.Normal(config.noise_xy_m);
    v.dyaw_rad =
        dyaw + stats.yaw_drift_rad_per_m * ds + slip_yaw_rad + rng.Normal(config.noise_yaw_rad);
    v.dz_m = dz + rng.Normal(config.noise_z_m);
    v.droll_rad = droll + rng.Normal(config.noise_roll_pitch_rad);
    v.dpitch_rad = dpitch + rng.Normal(config.noise_roll_pitch_rad);
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
