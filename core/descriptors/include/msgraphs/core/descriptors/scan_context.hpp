// SPDX-License-Identifier: MIT
// Scan Context (Kim and Kim, IROS 2018), fixed size: a polar grid of rings x sectors around the
// cloud's origin holding the highest point per cell; a ring key (row means, rotation-invariant)
// for nearest-neighbour search; a sector key (column means) to pick the yaw shifts worth trying;
// and the column-shift cosine distance, which also returns the yaw between the two clouds.
// Storage is a fixed array (at most 40 x 120): building and comparing never allocate.
#pragma once

#include <Eigen/Core>
#include <array>
#include <span>

#include "msgraphs/base/expected.hpp"

namespace msgraphs::core {

struct ScanContextConfig {
  int rings = 20;
  int sectors = 60;
  /// Points farther (in xy) are ignored. The outdoor default is 80 m; a room-centred cloud wants
  /// about the room's half diagonal plus a margin.
  float max_radius_m = 12.0f;
  /// Added to z before taking the cell maximum; cells hold max(z + offset, 0). With clouds whose
  /// z is height above the floor, 0 is right.
  float height_offset_m = 0.0f;

  Status Validate() const;
};

class ScanContext {
 public:
  static constexpr int kMaxRings = 40;
  static constexpr int kMaxSectors = 120;

  /// Builds from points in the descriptor's frame (origin at the room centre, z up). Non-finite
  /// points are skipped. kDegenerate when no point falls inside max_radius_m.
  Status Build(std::span<const Eigen::Vector3f> points, const ScanContextConfig& config);

  int rings() const { return rings_; }
  int sectors() const { return sectors_; }
  float cell(int ring, int sector) const { return cells_[static_cast<std::size_t>(ring * kMaxSectors + sector)]; }
  float ring_key(int ring) const { return ring_key_[static_cast<std::size_t>(ring)]; }
  float sector_key(int sector) const { return sector_key_[static_cast<std::size_t>(sector)]; }
  float column_norm(int sector) const { return column_norm_[static_cast<std::size_t>(sector)]; }
  /// Column `sector` divided by its norm, rings contiguous (zero for an empty column): the
  /// distance is then one contiguous dot product per column pair.
  const float* unit_column(int sector) const { return &unit_columns_[static_cast<std::size_t>(sector * kMaxRings)]; }
  std::size_t points_used() const { return points_used_; }
  float max_radius_m() const { return max_radius_; }

  /// Restores a descriptor received from elsewhere (cells row-major, rings x sectors).
  Status FromCells(int rings, int sectors, float max_radius_m, std::span<const float> cells);

 private:
  void ComputeKeys();

  int rings_ = 0;
  int sectors_ = 0;
  float max_radius_ = 0;
  std::size_t points_used_ = 0;
  std::array<float, kMaxRings * kMaxSectors> cells_{};
  std::array<float, kMaxRings> ring_key_{};
  std::array<float, kMaxSectors> sector_key_{};
  std::array<float, kMaxSectors> column_norm_{};
  std::array<float, kMaxSectors * kMaxRings> unit_columns_{};
};

struct ScanContextMatch {
  float distance = 1.0f;  ///< 0 (identical) .. 1; 1 when the two share no non-empty column
  int shift = 0;          ///< sectors
  /// Rotation about z that maps the second cloud's frame into the first's: p_a = Rz(yaw) p_b,
  /// to within one sector (360 / sectors degrees).
  float yaw_rad = 0.0f;
};

/// Distance between two descriptors of the same size (kInvalidArgument otherwise). With
/// `search_all_shifts` false only the shifts within +-search_radius sectors of the sector-key
/// alignment and of its three quarter-turn alternatives are tried (rooms are nearly symmetric,
/// so the key alone cannot tell a rectangle's quarter turns apart): 28 of 60 shifts.
Expected<ScanContextMatch> ScanContextDistance(const ScanContext& a, const ScanContext& b,
                                               bool search_all_shifts = false, int search_radius = 3);

}  // namespace msgraphs::core
