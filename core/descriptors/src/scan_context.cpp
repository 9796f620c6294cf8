// SPDX-License-Identifier: MIT
#include "msgraphs/core/descriptors/scan_context.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace msgraphs::core {
namespace {

// atan2 with a minimax polynomial for atan on [0, 1] (max error about 1e-5 rad): the standard
// one dominated the descriptor's build time.
float FastAtan2(float y, float x) {
  const float ax = std::fabs(x), ay = std::fabs(y);
  const float mx = std::max(ax, ay);
  if (mx == 0.0f) return 0.0f;
  const float a = std::min(ax, ay) / mx;
  const float s = a * a;
  float r = ((-0.0464964749f * s + 0.15931422f) * s - 0.327622764f) * s * a + a;
  if (ay > ax) r = 1.57079637f - r;
  if (x < 0.0f) r = 3.14159274f - r;
  return y < 0.0f ? -r : r;
}

}  // namespace

Status ScanContextConfig::Validate() const {
  if (rings < 1 || rings > ScanContext::kMaxRings || sectors < 4 || sectors > ScanContext::kMaxSectors) {
    return Error{Errc::kInvalidConfig, "scan context: rings must be 1..40 and sectors 4..120"};
  }
  if (!(max_radius_m > 0.0f) || !std::isfinite(max_radius_m) || !std::isfinite(height_offset_m)) {
    return Error{Errc::kInvalidConfig, "scan context: max radius must be > 0"};
  }
  return Ok();
}

Status ScanContext::Build(std::span<const Eigen::Vector3f> points, const ScanContextConfig& config) {
  if (Status s = config.Validate(); !s) return s;
  rings_ = config.rings;
  sectors_ = config.sectors;
  max_radius_ = config.max_radius_m;
  points_used_ = 0;
  cells_.fill(0.0f);
  const float two_pi = 2.0f * std::numbers::pi_v<float>;
  for (const Eigen::Vector3f& p : points) {
    if (!p.allFinite()) continue;
    const float r2 = p.x() * p.x() + p.y() * p.y();
    if (r2 > max_radius_ * max_radius_) continue;
    const float r = std::sqrt(r2);
    float theta = FastAtan2(p.y(), p.x());  // sectors are 6 degrees: 1e-5 rad is plenty
    if (theta < 0.0f) theta += two_pi;
    int ring = static_cast<int>(r / max_radius_ * static_cast<float>(rings_));
    int sector = static_cast<int>(theta / two_pi * static_cast<float>(sectors_));
    if (ring >= rings_) ring = rings_ - 1;
    if (sector >= sectors_) sector = sectors_ - 1;
    float& cell = cells_[static_cast<std::size_t>(ring * kMaxSectors + sector)];
    const float value = p.z() + config.height_offset_m;
    if (value > cell) cell = value;
    ++points_used_;
  }
  ComputeKeys();
  if (points_used_ == 0) return Error{Errc::kDegenerate, "scan context: no point within the radius"};
  return Ok();
}

Status ScanContext::FromCells(int rings, int sectors, float max_radius_m, std::span<const float> cells) {
  ScanContextConfig c;
  c.rings = rings;
  c.sectors = sectors;
  c.max_radius_m = max_radius_m;
  if (Status s = c.Validate(); !s) return s;
  if (cells.size() != static_cast<std::size_t>(rings * sectors)) {
    return Error{Errc::kInvalidArgument, "scan context: cell count does not match the size"};
  }
  rings_ = rings;
  sectors_ = sectors;
  max_radius_ = max_radius_m;
  cells_.fill(0.0f);
  points_used_ = 0;
  for (int r = 0; r < rings; ++r) {
    for (int s = 0; s < sectors; ++s) {
      const float v = cells[static_cast<std::size_t>(r * sectors + s)];
      if (!std::isfinite(v) || v < 0.0f || v > 1000.0f) {
        return Error{Errc::kMalformed, "scan context: cell values must be finite, 0..1000"};
      }
      cells_[static_cast<std::size_t>(r * kMaxSectors + s)] = v;
      points_used_ += v > 0.0f ? 1 : 0;
    }
  }
  ComputeKeys();
  return Ok();
}

void ScanContext::ComputeKeys() {
  ring_key_.fill(0.0f);
  sector_key_.fill(0.0f);
  column_norm_.fill(0.0f);
  for (int r = 0; r < rings_; ++r) {
    for (int s = 0; s < sectors_; ++s) {
      const float v = cell(r, s);
      ring_key_[static_cast<std::size_t>(r)] += v;
      sector_key_[static_cast<std::size_t>(s)] += v;
      column_norm_[static_cast<std::size_t>(s)] += v * v;
    }
  }
  for (int r = 0; r < rings_; ++r) ring_key_[static_cast<std::size_t>(r)] /= static_cast<float>(sectors_);
  unit_columns_.fill(0.0f);
  for (int s = 0; s < sectors_; ++s) {
    const auto us = static_cast<std::size_t>(s);
    sector_key_[us] /= static_cast<float>(rings_);
    column_norm_[us] = std::sqrt(column_norm_[us]);
    if (column_norm_[us] <= 0.0f) continue;
    for (int r = 0; r < rings_; ++r) {
      unit_columns_[us * kMaxRings + static_cast<std::size_t>(r)] = cell(r, s) / column_norm_[us];
    }
  }
}

namespace {

// Mean cosine distance over columns non-empty in both, with b's column c compared to a's
// column (c + shift) mod N. Columns are stored unit-length and contiguous; the default 20
// rings get a fixed-size (fully unrolled SIMD) dot product.
template <int kRings>
float ShiftedDistanceT(const ScanContext& a, const ScanContext& b, int shift) {
  const int n = a.sectors();
  const int rings = a.rings();
  using Column = Eigen::Matrix<float, kRings, 1>;
  float sum = 0.0f;
  int used = 0;
  // Empty columns are stored as zeros, so every pair can be multiplied without a branch; only
  // the count of columns non-empty in both needs the norms.
  for (int c = 0; c < n; ++c) {
    int ca = c + shift;
    if (ca >= n) ca -= n;
    sum += Eigen::Map<const Column>(a.unit_column(ca), rings).dot(Eigen::Map<const Column>(b.unit_column(c), rings));
    used += static_cast<int>(a.column_norm(ca) > 0.0f) & static_cast<int>(b.column_norm(c) > 0.0f);
  }
  return used == 0 ? 1.0f : 1.0f - sum / static_cast<float>(used);
}

float ShiftedDistance(const ScanContext& a, const ScanContext& b, int shift) {
  return a.rings() == 20 ? ShiftedDistanceT<20>(a, b, shift) : ShiftedDistanceT<Eigen::Dynamic>(a, b, shift);
}

}  // namespace

Expected<ScanContextMatch> ScanContextDistance(const ScanContext& a, const ScanContext& b, bool search_all_shifts,
                                               int search_radius) {
  if (a.rings() != b.rings() || a.sectors() != b.sectors() || a.rings() == 0) {
    return Error{Errc::kInvalidArgument, "scan context: descriptors differ in size"};
  }
  const int n = a.sectors();
  ScanContextMatch best;
  best.distance = 2.0f;
  auto consider = [&](int shift) {
    shift = ((shift % n) + n) % n;
    const float d = ShiftedDistance(a, b, shift);
    if (d < best.distance) {
      best.distance = d;
      best.shift = shift;
    }
  };
  if (search_all_shifts) {
    for (int s = 0; s < n; ++s) consider(s);
  } else {
    // The shift that best aligns the sector keys, then its neighbourhood.
    int key_shift = 0;
    float key_best = 3.4e38f;
    for (int s = 0; s < n; ++s) {
      float d = 0.0f;  // two runs instead of a modulo per element
      for (int c = 0; c < n - s; ++c) {
        const float e = a.sector_key(c + s) - b.sector_key(c);
        d += e * e;
      }
      for (int c = n - s; c < n; ++c) {
        const float e = a.sector_key(c + s - n) - b.sector_key(c);
        d += e * e;
      }
      if (d < key_best) {
        key_best = d;
        key_shift = s;
      }
    }
    // Rooms are nearly symmetric: a rectangle's sector key aligns almost as well a quarter or
    // a half turn away. Try the neighbourhood of all four quarter-turn alternatives.
    for (int quarter = 0; quarter < 4; ++quarter) {
      const int base = key_shift + quarter * n / 4;
      for (int k = -search_radius; k <= search_radius; ++k) consider(base + k);
    }
  }
  if (best.distance > 1.0f) best.distance = 1.0f;
  // b's column c lines up with a's column c + shift: b's frame is turned by -shift sectors
  // relative to a's, so p_a = Rz(shift * sector_angle) p_b.
  const float sector_angle = 2.0f * std::numbers::pi_v<float> / static_cast<float>(n);
  float yaw = static_cast<float>(best.shift) * sector_angle;
  if (yaw > std::numbers::pi_v<float>) yaw -= 2.0f * std::numbers::pi_v<float>;
  best.yaw_rad = yaw;
  return best;
}

}  // namespace msgraphs::core
