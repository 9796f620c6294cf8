// SPDX-License-Identifier: MIT
// Downsampled keyframe clouds (base frame) for the local map and loop-closure verification, in
// one ring of points sized at Init. When a new cloud does not fit, the oldest clouds are
// evicted (counted): a loop closure to an evicted keyframe is then impossible, which the mapper
// counts too. A cloud larger than the whole ring is refused. Nothing allocates after Init
// (KeyframeCloudStore.PuttingAndGettingAllocateNothingAfterInit).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

#include "msgraphs/base/expected.hpp"

namespace msgraphs::core {

class KeyframeCloudStore {
 public:
  /// `max_keys`: keyframe ids are below it; `max_points`: the ring.
  void Init(std::size_t max_keys, std::size_t max_points);

  /// Stores (replacing what `key` held). `sequence` tells a reused key from its previous owner.
  Status Put(std::uint32_t key, std::uint64_t sequence, std::span<const Eigen::Vector3f> points);
  /// The cloud, or an empty span when it was evicted or never stored.
  std::span<const Eigen::Vector3f> Get(std::uint32_t key, std::uint64_t sequence) const;

  std::size_t used_points() const { return used_; }
  std::size_t peak_points() const { return peak_; }
  std::size_t capacity_points() const { return points_.size(); }
  std::uint64_t evicted() const { return evicted_; }

 private:
  struct Entry {
    std::size_t offset = 0, count = 0;
    std::uint64_t sequence = 0;
    bool valid = false;
  };
  void EvictFront();
  std::vector<Eigen::Vector3f> points_;
  std::vector<Entry> entries_;
  std::vector<std::uint32_t> order_;  // ring of keys in insertion order (oldest at order_head_)
  std::vector<std::uint64_t> order_sequence_;
  std::size_t order_head_ = 0, order_size_ = 0;
  std::size_t write_ = 0, used_ = 0, peak_ = 0;
  std::uint64_t evicted_ = 0;
};

}  // namespace msgraphs::core
