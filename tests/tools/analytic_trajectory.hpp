// SPDX-License-Identifier: MIT
// A known smooth trajectory for the truth-pairing and ATE tests: a Lissajous curve that rolls,
// pitches and yaws at varying rates, with the maxima of its derivatives in closed form so that
// tests can state interpolation bounds instead of picking tolerances.
#pragma once

#include <Eigen/Geometry>
#include <cmath>
#include <vector>

#include "msgraphs/tools/tum.hpp"

namespace msgraphs::test {

/// Stamps are UNIX seconds, as the recordings' (their double precision then matters: ~0.2 us).
inline constexpr double kT0 = 1763811046.0;

// p(s) = (3 sin 0.4s, 2 sin 0.6s, 0.1 sin 0.3s), s = t - kT0.
inline const double kMaxSpeed_m_s = std::sqrt(1.2 * 1.2 + 1.2 * 1.2 + 0.03 * 0.03);
inline const double kMaxAcceleration_m_s2 = std::sqrt(0.48 * 0.48 + 0.72 * 0.72 + 0.009 * 0.009);
// yaw = 0.5s + 0.3 sin s, pitch = 0.04 cos 0.9s, roll = 0.05 sin 0.7s (Z-Y-X).
inline const double kMaxRate_rad_s = 0.8 + 0.036 + 0.035;
/// Geodesic interpolation over dt is off by at most about dt^2 / 8 times the angular
/// acceleration plus the square of the rate (the rotation axis turning): both summed here.
inline const double kMaxAngularBound_rad_s2 =
    (0.3 + 0.0324 + 0.0245) + kMaxRate_rad_s * kMaxRate_rad_s;
/// Stamps near 1.8e9 s carry ~0.2 us of rounding and TUM files keep 1 us: a pose is known
/// only to within this much time.
inline constexpr double kStampResolution_s = 1e-6;

inline Eigen::Isometry3d AnalyticPose(double t) {
  const double s = t - kT0;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() << 3 * std::sin(0.4 * s), 2 * std::sin(0.6 * s), 0.1 * std::sin(0.3 * s);
  T.linear() = (Eigen::AngleAxisd(0.5 * s + 0.3 * std::sin(s), Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(0.04 * std::cos(0.9 * s), Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(0.05 * std::sin(0.7 * s), Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  return T;
}

/// The truth sampled at `rate_hz` over [kT0 + from_s, kT0 + to_s].
inline std::vector<tools::StampedPose> SampleTruth(double rate_hz, double from_s, double to_s) {
  std::vector<tools::StampedPose> out;
  const auto n = static_cast<int>(std::floor((to_s - from_s) * rate_hz + 1e-9));
  for (int i = 0; i <= n; ++i) {
    const double t = kT0 + from_s + i / rate_hz;
    out.push_back({t, AnalyticPose(t)});
  }
  return out;
}

}  // namespace msgraphs::test
