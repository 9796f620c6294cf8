// SPDX-License-Identifier: MIT
#include "msgraphs/drivers/can_odometry/odometry_integrator.hpp"

#include <cmath>

namespace msgraphs::drivers::can_odometry {
namespace {

void Normalise(Pose3& p) {
  const double n = std::sqrt(p.qw * p.qw + p.qx * p.qx + p.qy * p.qy + p.qz * p.qz);
  p.qw /= n;
  p.qx /= n;
  p.qy /= n;
  p.qz /= n;
}

// v' = q v q*, expanded.
void Rotate(const Pose3& q, double& x, double& y, double& z) {
  const double tx = 2.0 * (q.qy * z - q.qz * y);
  const double ty = 2.0 * (q.qz * x - q.qx * z);
  const double tz = 2.0 * (q.qx * y - q.qy * x);
  const double rx = x + q.qw * tx + (q.qy * tz - q.qz * ty);
  const double ry = y + q.qw * ty + (q.qz * tx - q.qx * tz);
  const double rz = z + q.qw * tz + (q.qx * ty - q.qy * tx);
  x = rx;
  y = ry;
  z = rz;
}

}  // namespace

Pose3 OdometryIntegrator::Integrate(const Twist& twist, double duration_s, double period_s) {
  // Constant body velocity over `duration_s`, in sub-steps of about one sample period; each
  // sub-step moves along the chord at half its rotation (midpoint rule), which follows an arc
  // to second order, as the encoders themselves would have reported it.
  int steps = static_cast<int>(std::ceil(duration_s / period_s));
  if (steps < 1) steps = 1;
  if (steps > 256) steps = 256;
  const double h = duration_s / steps;
  const Pose3 half = PoseFromDelta(0, 0, 0, 0.5 * twist.wroll * h, 0.5 * twist.wpitch * h, 0.5 * twist.wyaw * h);
  const Pose3 move = PoseFromDelta(twist.vx * h, twist.vy * h, twist.vz * h, 0, 0, 0);
  const Pose3 sub = Compose(Compose(half, move), half);
  Pose3 total;
  for (int i = 0; i < steps; ++i) total = Compose(total, sub);
  return total;
}

Pose3 Compose(const Pose3& a, const Pose3& b) {
  Pose3 c;
  double x = b.x_m, y = b.y_m, z = b.z_m;
  Rotate(a, x, y, z);
  c.x_m = a.x_m + x;
  c.y_m = a.y_m + y;
  c.z_m = a.z_m + z;
  c.qw = a.qw * b.qw - a.qx * b.qx - a.qy * b.qy - a.qz * b.qz;
  c.qx = a.qw * b.qx + a.qx * b.qw + a.qy * b.qz - a.qz * b.qy;
  c.qy = a.qw * b.qy - a.qx * b.qz + a.qy * b.qw + a.qz * b.qx;
  c.qz = a.qw * b.qz + a.qx * b.qy - a.qy * b.qx + a.qz * b.qw;
  Normalise(c);
  return c;
}

Pose3 PoseFromDelta(double dx_m, double dy_m, double dz_m, double droll_rad, double dpitch_rad,
                    double dyaw_rad) {
  // R = Rz(yaw) Ry(pitch) Rx(roll) as a quaternion product of the three axis rotations.
  const double cr = std::cos(droll_rad / 2), sr = std::sin(droll_rad / 2);
  const double cp = std::cos(dpitch_rad / 2), sp = std::sin(dpitch_rad / 2);
  const double cy = std::cos(dyaw_rad / 2), sy = std::sin(dyaw_rad / 2);
  Pose3 p;
  p.qw = cy * cp * cr + sy * sp * sr;
  p.qx = cy * cp * sr - sy * sp * cr;
  p.qy = cy * sp * cr + sy * cp * sr;
  p.qz = sy * cp * cr - cy * sp * sr;
  p.x_m = dx_m;
  p.y_m = dy_m;
  p.z_m = dz_m;
  return p;
}

Status OdometryIntegratorConfig::Validate() const {
  if (!(nominal_period_s > 0.0) || nominal_period_s > 1.0) {
    return Error{Errc::kInvalidConfig, "odometry: nominal period must be in (0, 1] s"};
  }
  if (max_bridge < Duration()) return Error{Errc::kInvalidConfig, "odometry: negative max_bridge"};
  return Ok();
}

Expected<OdometryIntegrator> OdometryIntegrator::Create(const OdometryIntegratorConfig& config) {
  if (Status s = config.Validate(); !s) return s.error();
  return OdometryIntegrator(config);
}

Expected<OdometryPose> OdometryIntegrator::Add(const OdomSample& sample) {
  const OdomSampleValues& v = sample.values;
  const bool valid = (v.status & kStatusValid) != 0;
  OdometryPose out;
  out.sequence = v.sequence;
  out.sample_time_us = v.sample_time_us;
  if ((v.status & kStatusSlipSuspected) != 0) {
    out.flags |= kPoseSlipSuspected;
    ++stats_.slip_samples;
  }

  if (!started_) {
    // The first sample's motion happened before the trajectory's origin: it defines t = 0.
    started_ = true;
    last_sequence_ = v.sequence;
    last_sample_time_us_ = v.sample_time_us;
    unwrapped_us_ = v.sample_time_us;
    period_estimate_s_ = config_.nominal_period_s;
    ++stats_.samples;
    if (!valid) {
      out.flags |= kPoseInvalidSample;
      ++stats_.invalid_samples;
    }
    out.stamp = UnixTime::FromNanoseconds(
        clock_.Update(unwrapped_us_ * 1000, sample.receive_time.nanoseconds_since_epoch()));
    out.T_odom_base = pose_;
    return out;
  }

  // Unwrap the 32-bit microsecond clock; a step above 2^31 us is a step backwards.
  const std::uint32_t forward_us = v.sample_time_us - last_sample_time_us_;
  const auto seq_step = static_cast<std::uint8_t>(v.sequence - last_sequence_);
  if (forward_us == 0 || forward_us > 0x80000000u) {
    if (forward_us == 0 && seq_step == 0) {
      ++stats_.duplicates;
      return Error{Errc::kOutOfOrder, "odometry: duplicate sample"};
    }
    ++stats_.out_of_order;
    return Error{Errc::kOutOfOrder, "odometry: sample time went backwards"};
  }
  const double dt_s = static_cast<double>(forward_us) * 1e-6;

  // How many samples are missing: from the sequence, unless the time says the 8-bit counter
  // wrapped completely (a gap above 255 samples).
  auto missing = static_cast<std::int64_t>(seq_step) - 1;
  if (seq_step == 0) missing = 255;
  const auto by_time = static_cast<std::int64_t>(std::llround(dt_s / period_estimate_s_)) - 1;
  if (by_time > missing + 128) missing += ((by_time - missing + 128) / 256) * 256;
  if (missing < 0) missing = 0;

  // The sample's own delta covers its own interval; the rest of dt was missing.
  const double own_s = dt_s / static_cast<double>(missing + 1);
  const double missing_s = dt_s - own_s;
  Twist twist;
  if (valid) {
    twist = {v.dx_m / own_s, v.dy_m / own_s, v.dz_m / own_s,
             v.droll_rad / own_s, v.dpitch_rad / own_s, v.dyaw_rad / own_s};
  } else {
    twist = last_twist_;
    ++stats_.invalid_samples;
    out.flags |= kPoseInvalidSample;
  }

  Pose3 step;  // identity
  if (missing > 0) {
    ++stats_.gaps;
    stats_.missing_samples += static_cast<std::uint64_t>(missing);
    if (missing_s <= config_.max_bridge.seconds()) {
      // Mean of the velocities either side of the gap, over the missing time.
      Twist mean;
      mean.vx = 0.5 * (last_twist_.vx + twist.vx);
      mean.vy = 0.5 * (last_twist_.vy + twist.vy);
      mean.vz = 0.5 * (last_twist_.vz + twist.vz);
      mean.wroll = 0.5 * (last_twist_.wroll + twist.wroll);
      mean.wpitch = 0.5 * (last_twist_.wpitch + twist.wpitch);
      mean.wyaw = 0.5 * (last_twist_.wyaw + twist.wyaw);
      step = Integrate(mean, missing_s, period_estimate_s_);
      out.flags |= kPoseBridged;
      ++stats_.bridged;
      stats_.bridged_seconds += missing_s;
    } else {
      out.flags |= kPoseDiscontinuity;
      ++stats_.discontinuities;
    }
  } else if (dt_s < 3.0 * period_estimate_s_) {
    // Track the bridge's real rate from gap-free samples (slowly: one bad interval is noise).
    period_estimate_s_ += 0.05 * (dt_s - period_estimate_s_);
  }
  if (valid) {
    step = Compose(step, PoseFromDelta(v.dx_m, v.dy_m, v.dz_m, v.droll_rad, v.dpitch_rad, v.dyaw_rad));
  } else {
    step = Compose(step, Integrate(twist, own_s, period_estimate_s_));
    ++stats_.bridged;
    stats_.bridged_seconds += own_s;
  }
  pose_ = Compose(pose_, step);
  last_twist_ = twist;
  last_sequence_ = v.sequence;
  last_sample_time_us_ = v.sample_time_us;
  unwrapped_us_ += forward_us;
  ++stats_.samples;

  const std::uint64_t resets_before = clock_.resets();
  out.stamp = UnixTime::FromNanoseconds(
      clock_.Update(unwrapped_us_ * 1000, sample.receive_time.nanoseconds_since_epoch()));
  stats_.clock_resets += clock_.resets() - resets_before;
  out.T_odom_base = pose_;
  out.T_previous_current = step;
  out.step_duration_s = dt_s;
  return out;
}

}  // namespace msgraphs::drivers::can_odometry
