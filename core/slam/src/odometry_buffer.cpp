// SPDX-License-Identifier: MIT
#include "msgraphs/core/slam/odometry_buffer.hpp"
#include "msgraphs/base/snapshot_archive.hpp"

#include <cmath>

#include "msgraphs/core/geometry/se3.hpp"

namespace msgraphs::core {

void OdometryBuffer::Init(std::size_t capacity, double max_gap_s) {
  stamps_.assign(capacity < 2 ? 2 : capacity, 0.0);
  poses_.assign(stamps_.size(), Eigen::Isometry3d::Identity());
  head_ = size_ = 0;
  max_gap_s_ = max_gap_s;
  stats_ = {};
}

double OdometryBuffer::newest_stamp() const {
  return size_ == 0 ? -1e300 : stamps_[Index(size_ - 1)];
}

Status OdometryBuffer::Add(double stamp_s, const Eigen::Isometry3d& T_odom_base) {
  if (!std::isfinite(stamp_s) || !IsValidRigidTransform(T_odom_base, 1e-6)) {
    ++stats_.invalid;
    return Error{Errc::kInvalidArgument, "odometry pose not finite or not rigid"};
  }
  if (size_ > 0 && !(stamp_s > newest_stamp())) {
    ++stats_.out_of_order;
    return Error{Errc::kOutOfOrder, "odometry stamp not after the newest"};
  }
  if (size_ == stamps_.size()) {
    head_ = (head_ + 1) % stamps_.size();
    --size_;
    ++stats_.overwritten;
  }
  const std::size_t i = Index(size_);
  stamps_[i] = stamp_s;
  poses_[i] = T_odom_base;
  ++size_;
  ++stats_.accepted;
  return Ok();
}

Expected<OdometryLookup> OdometryBuffer::At(double stamp_s) const {
  if (size_ == 0 || stamp_s > newest_stamp())
    return Error{Errc::kWouldBlock, "odometry not there yet"};
  if (stamp_s < stamps_[Index(0)])
    return Error{Errc::kNotFound, "odometry before the oldest kept pose"};
  // Binary search over the ring for the first stamp >= stamp_s.
  std::size_t lo = 0, hi = size_ - 1;
  while (lo < hi) {
    const std::size_t mid = (lo + hi) / 2;
    if (stamps_[Index(mid)] < stamp_s)
      lo = mid + 1;
    else
      hi = mid;
  }
  OdometryLookup out;
  if (lo == 0 || stamps_[Index(lo)] == stamp_s) {
    out.T_odom_base = poses_[Index(lo)];
    return out;
  }
  const double t0 = stamps_[Index(lo - 1)], t1 = stamps_[Index(lo)];
  out.across_gap = t1 - t0 > max_gap_s_;
  out.T_odom_base =
      Interpolate(poses_[Index(lo - 1)], poses_[Index(lo)], (stamp_s - t0) / (t1 - t0));
  return out;
}


template <class Archive>
void OdometryBuffer::Io(Archive& ar) {
  IoSameSize(ar, stamps_.size());
  if (ar.failed()) return;
  ar(stamps_.data(), stamps_.size());
  for (Eigen::Isometry3d& T : poses_) ar(T.matrix().data(), 16);
  IoCount(ar, head_, stamps_.size() - 1);
  IoCount(ar, size_, stamps_.size());
  ar(stats_);  // max_gap_s_ is the config's (Init)
  if constexpr (Archive::kLoading) {
    // Interpolation divides by the step between stamps: they rise, as Add keeps them.
    for (std::size_t i = 0; i < size_; ++i) {
      if (!std::isfinite(stamps_[Index(i)]) || (i > 0 && !(stamps_[Index(i)] > stamps_[Index(i - 1)])))
        ar.Fail();
    }
  }
}

void OdometryBuffer::Save(SnapshotWriter& w) const { const_cast<OdometryBuffer*>(this)->Io(w); }
void OdometryBuffer::Load(SnapshotReader& r) { Io(r); }

}  // namespace msgraphs::core
