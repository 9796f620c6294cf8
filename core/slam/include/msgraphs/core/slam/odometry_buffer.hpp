// SPDX-License-Identifier: MIT
// A bounded, time-ordered buffer of encoder odometry poses T_odom_base with interpolation, the
// mapper's source of motion between and within scans. Capacity is fixed at Init; when full the
// oldest pose is overwritten (the mapper only looks back a few scans). Out-of-order and
// duplicate stamps and non-rigid poses are refused and counted; nothing allocates after Init.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "msgraphs/base/expected.hpp"

namespace msgraphs {
class SnapshotReader;
class SnapshotWriter;
}  // namespace msgraphs

namespace msgraphs::core {

struct OdometryLookup {
  Eigen::Isometry3d T_odom_base = Eigen::Isometry3d::Identity();
  /// The two poses around the stamp are further apart than the buffer's max gap: the motion
  /// between them is a guess (the CAN decoder bridged a gap, or samples were lost).
  bool across_gap = false;
};

struct OdometryBufferStats {
  std::uint64_t accepted = 0;
  std::uint64_t out_of_order = 0;  ///< stamp not after the newest (duplicates included)
  std::uint64_t invalid = 0;       ///< non-finite or non-rigid pose
  std::uint64_t overwritten = 0;   ///< oldest pose dropped because the buffer was full
};

class OdometryBuffer {
 public:
  /// Its state in a snapshot (LocalMapper::Save / Load): the reader fails on a store of another
  /// size or a value out of range.
  void Save(SnapshotWriter& w) const;
  void Load(SnapshotReader& r);
  void Init(std::size_t capacity, double max_gap_s = 0.1);

  Status Add(double stamp_s, const Eigen::Isometry3d& T_odom_base);

  /// Interpolated pose at `stamp_s`: kWouldBlock when it is after the newest pose (wait for
  /// more), kNotFound when before the oldest one kept.
  Expected<OdometryLookup> At(double stamp_s) const;

  std::size_t size() const { return size_; }
  /// The i-th pose kept, 0 the oldest (i < size()).
  double stamp(std::size_t i) const { return stamps_[Index(i)]; }
  const Eigen::Isometry3d& pose(std::size_t i) const { return poses_[Index(i)]; }
  /// Forgets every pose (statistics stay).
  void Clear() { head_ = size_ = 0; }
  std::size_t capacity() const { return stamps_.size(); }
  double newest_stamp() const;
  const OdometryBufferStats& stats() const { return stats_; }

 private:
  template <class Archive>
  void Io(Archive& ar);
  std::size_t Index(std::size_t i) const { return (head_ + i) % stamps_.size(); }  // i: 0 = oldest
  std::vector<double> stamps_;
  std::vector<Eigen::Isometry3d> poses_;
  std::size_t head_ = 0, size_ = 0;
  double max_gap_s_ = 0.1;
  OdometryBufferStats stats_;
};

}  // namespace msgraphs::core
