// SPDX-License-Identifier: MIT
#include "msgraphs/core/slam/keyframe_cloud_store.hpp"

#include <algorithm>

namespace msgraphs::core {

void KeyframeCloudStore::Init(std::size_t max_keys, std::size_t max_points) {
  points_.assign(max_points, Eigen::Vector3f::Zero());
  entries_.assign(max_keys, Entry{});
  // Every Put adds one order entry; stale ones (replaced keys) are skipped when evicted. A key
  // count's worth of live entries plus as many stale ones bounds the ring.
  order_.assign(2 * max_keys + 1, 0);
  order_sequence_.assign(order_.size(), 0);
  order_head_ = order_size_ = write_ = used_ = peak_ = 0;
  evicted_ = 0;
}

void KeyframeCloudStore::EvictFront() {
  const std::uint32_t key = order_[order_head_];
  const std::uint64_t sequence = order_sequence_[order_head_];
  order_head_ = (order_head_ + 1) % order_.size();
  --order_size_;
  Entry& e = entries_[key];
  if (e.valid && e.sequence == sequence) {
    e.valid = false;
    used_ -= e.count;
    ++evicted_;
  }
}

Status KeyframeCloudStore::Put(std::uint32_t key,
                               std::uint64_t sequence,
                               std::span<const Eigen::Vector3f> points) {
  if (key >= entries_.size())
    return Error{Errc::kInvalidArgument, "keyframe cloud key beyond capacity"};
  if (points.size() > points_.size())
    return Error{Errc::kCapacityExceeded, "keyframe cloud larger than the store"};
  Entry& old = entries_[key];
  if (old.valid) {
    used_ -= old.count;
    old.valid = false;
  }
  if (write_ + points.size() > points_.size()) write_ = 0;  // wrap; the tail stays unused
  const std::size_t begin = write_, end = write_ + points.size();
  // Evict, oldest first, every cloud overlapping [begin, end).
  while (order_size_ > 0) {
    const Entry& front = entries_[order_[order_head_]];
    const bool stale = !front.valid || front.sequence != order_sequence_[order_head_];
    const bool overlaps = front.offset < end && begin < front.offset + front.count;
    if (!stale && !overlaps) break;
    EvictFront();
  }
  if (order_size_ == order_.size()) EvictFront();
  std::copy(points.begin(), points.end(), points_.begin() + static_cast<std::ptrdiff_t>(begin));
  Entry& e = entries_[key];
  e.offset = begin;
  e.count = points.size();
  e.sequence = sequence;
  e.valid = true;
  const std::size_t tail = (order_head_ + order_size_) % order_.size();
  order_[tail] = key;
  order_sequence_[tail] = sequence;
  ++order_size_;
  write_ = end;
  used_ += points.size();
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

}  // namespace msgraphs::core
