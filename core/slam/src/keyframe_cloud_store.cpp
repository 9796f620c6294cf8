// SPDX-License-Identifier: MIT
#include "msgraphs/core/slam/keyframe_cloud_store.hpp"
#include "msgraphs/base/snapshot_archive.hpp"

#include <algorithm>

namespace msgraphs::core {

void KeyframeCloudStore::Init(std::size_t max_keys, std::size_t max_points, std::size_t reclaim_points) {
  points_.assign(max_points, Eigen::Vector3f::Zero());
  entries_.assign(max_keys, Entry{});
  // Every Put appends one order entry; stale ones (keys replaced or evicted) are dropped by the
  // next compaction, which runs when the order is full: a key count's worth of live entries
  // plus as many stale ones bounds it.
  order_.assign(2 * max_keys + 1, 0);
  order_stamp_.assign(order_.size(), 0);
  order_size_ = top_ = used_ = peak_ = live_ = 0;
  reclaim_ = std::min(reclaim_points, max_points);
  stamp_ = 0;
  stats_ = {};
}

bool KeyframeCloudStore::Live(std::size_t i) const {
  const Entry& e = entries_[order_[i]];
  return e.valid && e.stamp == order_stamp_[i];
}

void KeyframeCloudStore::Evict(std::uint32_t key, const CloudRetentionPolicy* policy, CloudRetention why) {
  Entry& e = entries_[key];
  e.valid = false;
  used_ -= e.count;
  --live_;
  ++stats_.evicted;
  if (policy == nullptr) return;
  if (why == CloudRetention::kGone) {
    ++stats_.evicted_gone;
  } else if (why == CloudRetention::kUnique) {
    ++stats_.evicted_uncovered;
  } else {
    ++stats_.evicted_covered;
  }
}

template <typename Take>
void KeyframeCloudStore::EvictPass(std::size_t goal, CloudRetentionPolicy* policy, Take take) {
  if (policy != nullptr) policy->BeginPass();
  for (std::size_t i = 0; i < order_size_ && points_.size() - used_ < goal; ++i) {
    if (!Live(i)) continue;
    const std::uint32_t key = order_[i];
    const CloudRetention why =
        policy != nullptr ? policy->Retention(key, entries_[key].sequence) : CloudRetention::kReplaceable;
    if (take(why)) Evict(key, policy, why);
  }
}

void KeyframeCloudStore::MakeRoom(std::size_t need, CloudRetentionPolicy* policy) {
  const std::size_t target = std::max(need, reclaim_);
  const auto free_points = [this]() { return points_.size() - used_; };
  for (;;) {
    if (free_points() >= target) break;
    // Clouds nothing needs first, then the older clouds of the places the robot is at now.
    EvictPass(target, policy, [](CloudRetention why) {
      return why == CloudRetention::kGone || why == CloudRetention::kReplaceable;
    });
    if (policy == nullptr || free_points() >= target) break;
    EvictPass(target, policy, [](CloudRetention why) { return why == CloudRetention::kRevisited; });
    if (free_points() >= target || !policy->Coarsen()) break;
  }
  // Still short of what the new cloud needs: unique clouds go, oldest first, never pinned ones.
  if (free_points() < need && policy != nullptr) {
    EvictPass(need, policy, [](CloudRetention why) { return why != CloudRetention::kPinned; });
  }
  Compact();
}

void KeyframeCloudStore::Compact() {
  // Order is address order (appended at the top, kept by every compaction), so each live cloud
  // moves down or stays: a forward copy never overwrites what it has still to read.
  std::size_t write = 0, kept = 0;
  for (std::size_t i = 0; i < order_size_; ++i) {
    if (!Live(i)) continue;
    Entry& e = entries_[order_[i]];
    if (e.offset != write) {
      const auto from = points_.begin() + static_cast<std::ptrdiff_t>(e.offset);
      std::copy(from, from + static_cast<std::ptrdiff_t>(e.count),
                points_.begin() + static_cast<std::ptrdiff_t>(write));
      e.offset = write;
    }
    write += e.count;
    order_[kept] = order_[i];
    order_stamp_[kept] = order_stamp_[i];
    ++kept;
  }
  order_size_ = kept;
  top_ = write;
  ++stats_.compactions;
}

Status KeyframeCloudStore::Put(std::uint32_t key,
                               std::uint64_t sequence,
                               std::span<const Eigen::Vector3f> points,
                               CloudRetentionPolicy* policy) {
  if (key >= entries_.size())
    return Error{Errc::kInvalidArgument, "keyframe cloud key beyond capacity"};
  if (points.size() > points_.size()) {
    ++stats_.refused;
    return Error{Errc::kCapacityExceeded, "keyframe cloud larger than the store"};
  }
  Entry& old = entries_[key];
  if (old.valid) {  // replaced: its points are freed by the next compaction
    old.valid = false;
    used_ -= old.count;
    --live_;
  }
  if (top_ + points.size() > points_.size() || order_size_ == order_.size()) {
    MakeRoom(points.size(), policy);
    if (top_ + points.size() > points_.size()) {
      ++stats_.refused;
      return Error{Errc::kCapacityExceeded, "keyframe cloud store holds only pinned clouds"};
    }
  }
  std::copy(points.begin(), points.end(), points_.begin() + static_cast<std::ptrdiff_t>(top_));
  Entry& e = entries_[key];
  e.offset = top_;
  e.count = points.size();
  e.sequence = sequence;
  e.stamp = ++stamp_;
  e.valid = true;
  order_[order_size_] = key;
  order_stamp_[order_size_] = e.stamp;
  ++order_size_;
  top_ += points.size();
  used_ += points.size();
  ++live_;
  peak_ = std::max(peak_, used_);
  return Ok();
}

std::span<const Eigen::Vector3f> KeyframeCloudStore::Get(std::uint32_t key,
                                                         std::uint64_t sequence) const {
  if (key >= entries_.size()) return {};
  const Entry& e = entries_[key];
  if (!e.valid || e.sequence != sequence) return {};
  return std::span<const Eigen::Vector3f>(points_.data() + e.offset, e.count);
}


template <class Archive>
void KeyframeCloudStore::Io(Archive& ar) {
  IoSameSize(ar, points_.size());
  IoSameSize(ar, entries_.size());
  if (ar.failed()) return;
  // The points in use only: below top_, the live clouds and the gaps compaction has not closed.
  IoCount(ar, top_, points_.size());
  for (std::size_t i = 0; i < top_; ++i) ar(points_[i].data(), 3);
  for (Entry& e : entries_) {
    ar(e.offset);
    ar(e.count);
    ar(e.sequence);
    ar(e.stamp);
    IoBool(ar, e.valid);
  }
  IoCount(ar, order_size_, order_.size());
  for (std::size_t i = 0; i < order_size_; ++i) {
    ar(order_[i]);
    ar(order_stamp_[i]);
    if constexpr (Archive::kLoading) {
      if (order_[i] >= entries_.size()) {
        ar.Fail();
        order_[i] = 0;
      }
    }
  }
  ar(stamp_);
  IoCount(ar, used_, points_.size());
  IoCount(ar, peak_, points_.size());
  IoCount(ar, live_, entries_.size());
  ar(stats_);  // reclaim_ is the config's (Init)
  if constexpr (Archive::kLoading) {
    if (!ar.failed() && !Consistent()) ar.Fail();
  }
}

// What Put, eviction and compaction rely on, as they leave it: the order lists each put once
// with rising stamps no newer than the store's count; every listed cloud has exactly one live
// order entry; live clouds lie in order, apart, below top_; the counts are what the entries say.
bool KeyframeCloudStore::Consistent() const {
  std::uint64_t last_stamp = 0;
  std::size_t end = 0, live = 0, used = 0;
  for (std::size_t i = 0; i < order_size_; ++i) {
    if (order_stamp_[i] <= last_stamp || order_stamp_[i] > stamp_) return false;
    last_stamp = order_stamp_[i];
    if (!Live(i)) continue;
    const Entry& e = entries_[order_[i]];
    if (e.offset < end || e.offset > top_ || e.count > top_ - e.offset) return false;
    end = e.offset + e.count;
    ++live;
    used += e.count;
  }
  std::size_t valid = 0;
  for (const Entry& e : entries_) valid += e.valid ? 1u : 0u;
  return live == valid && live == live_ && used == used_ && peak_ >= used_;
}

void KeyframeCloudStore::Save(SnapshotWriter& w) const { const_cast<KeyframeCloudStore*>(this)->Io(w); }
void KeyframeCloudStore::Load(SnapshotReader& r) { Io(r); }

}  // namespace msgraphs::core
