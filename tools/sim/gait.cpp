// SPDX-License-Identifier: MIT
#include "gait.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "random.hpp"
#include "trajectory.hpp"

namespace msgraphs::sim {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;

// Convolution with a Hann window of half-width `half` samples: smooth (the window has a
// continuous derivative) and exactly zero where the input is zero over the whole window.
std::vector<double> HannSmooth(const std::vector<double>& x, int half) {
  if (half < 1) return x;
  std::vector<double> w(static_cast<std::size_t>(2 * half + 1));
  double sum = 0;
  for (int j = -half; j <= half; ++j) {
    const double v = 0.5 * (1.0 + std::cos(std::numbers::pi * j / (half + 1)));
    w[static_cast<std::size_t>(j + half)] = v;
    sum += v;
  }
  const auto n = static_cast<std::int64_t>(x.size());
  std::vector<double> y(x.size(), 0.0);
  for (std::int64_t i = 0; i < n; ++i) {
    double acc = 0;
    for (int j = -half; j <= half; ++j) {
      const std::int64_t k = std::clamp<std::int64_t>(i + j, 0, n - 1);  // hold the ends
      acc += w[static_cast<std::size_t>(j + half)] * x[static_cast<std::size_t>(k)];
    }
    y[static_cast<std::size_t>(i)] = acc / sum;
  }
  return y;
}

// Cubic Hermite on [0, 1] between values a, b with slopes ma, mb (per unit of s).
double Hermite(double a, double ma, double b, double mb, double s) {
  const double s2 = s * s, s3 = s2 * s;
  return (2 * s3 - 3 * s2 + 1) * a + (s3 - 2 * s2 + s) * ma + (-2 * s3 + 3 * s2) * b +
         (s3 - s2) * mb;
}

}  // namespace

GaitParams GaitParams::Draw(const GaitConfig& config, std::uint64_t seed, int robot) {
  Random r = Random::Stream(seed, 0x67616974, static_cast<std::uint64_t>(robot));  // "gait"
  GaitParams g;
  g.config = config;
  g.bob_m = r.Uniform(config.bob_min_m, config.bob_max_m);
  g.roll_rad = r.Uniform(config.roll_min_deg, config.roll_max_deg) * kDegToRad;
  g.pitch_rad = r.Uniform(config.pitch_min_deg, config.pitch_max_deg) * kDegToRad;
  g.roll_phase_rad = r.Uniform(0, 2 * std::numbers::pi);
  g.pitch_phase_rad = r.Uniform(0, 2 * std::numbers::pi);
  g.start_phase_rad = r.Uniform(0, 2 * std::numbers::pi);
  if (!config.enabled) g.bob_m = g.roll_rad = g.pitch_rad = 0;
  return g;
}

void GaitTrack::Build(const std::vector<PlanarPose>& samples,
                      double dt_s,
                      const GaitParams& params) {
  params_ = params;
  dt_s_ = dt_s;
  const std::size_t n = samples.size();
  phase_rad_.assign(n, params.start_phase_rad);
  rate_rad_s_.assign(n, 0.0);
  envelope_.assign(n, 0.0);
  if (n == 0) return;
  const GaitConfig& c = params.config;
  // How much the legs are trotting, from the speed and the turn rate of each sample interval.
  std::vector<double> activity(n, 0.0), speed(n, 0.0);
  for (std::size_t i = 1; i < n; ++i) {
    const double v =
        std::hypot(samples[i].x - samples[i - 1].x, samples[i].y - samples[i - 1].y) / dt_s;
    const double w =
        std::fabs(std::remainder(samples[i].yaw - samples[i - 1].yaw, 2 * std::numbers::pi)) / dt_s;
    speed[i] = v;
    activity[i] = std::clamp(std::max(v / c.trot_speed_mps, w / c.trot_turn_rate_rps), 0.0, 1.0);
  }
  const int half = static_cast<int>(std::lround(c.settle_s / dt_s));
  envelope_ = HannSmooth(activity, half);
  const std::vector<double> smooth_speed = HannSmooth(speed, half);
  for (std::size_t i = 0; i < n; ++i) {
    const double f =
        c.step_rate_slow_hz + (c.step_rate_fast_hz - c.step_rate_slow_hz) *
                                  std::clamp(smooth_speed[i] / c.full_speed_mps, 0.0, 1.0);
    rate_rad_s_[i] = 2 * std::numbers::pi * f;
    if (i > 0)
      phase_rad_[i] = phase_rad_[i - 1] + 0.5 * (rate_rad_s_[i - 1] + rate_rad_s_[i]) * dt_s;
  }
}

GaitOffsets GaitTrack::At(double u) const {
  if (envelope_.empty()) return {};
  const std::size_t n = envelope_.size();
  u = std::clamp(u, 0.0, static_cast<double>(n - 1));
  const auto i = std::min(static_cast<std::size_t>(std::floor(u)), n - 1);
  const std::size_t j = std::min(i + 1, n - 1);
  const double s = u - static_cast<double>(i);
  // Catmull-Rom slopes for the envelope, the exact rate for the phase.
  const auto slope = [&](std::size_t k) {
    const std::size_t lo = k == 0 ? 0 : k - 1, hi = std::min(k + 1, n - 1);
    return hi == lo ? 0.0 : (envelope_[hi] - envelope_[lo]) / static_cast<double>(hi - lo);
  };
  const double e = Hermite(envelope_[i], slope(i), envelope_[j], slope(j), s);
  const double phi =
      Hermite(phase_rad_[i], rate_rad_s_[i] * dt_s_, phase_rad_[j], rate_rad_s_[j] * dt_s_, s);
  GaitOffsets o;
  o.z_m = params_.bob_m * e * std::cos(phi);
  o.pitch_rad = params_.pitch_rad * e * std::sin(phi + params_.pitch_phase_rad);
  o.roll_rad = params_.roll_rad * e * std::sin(0.5 * phi + params_.roll_phase_rad);
  return o;
}

}  // namespace msgraphs::sim
