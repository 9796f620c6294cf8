// SPDX-License-Identifier: MIT
// A 3-D k-d tree with bounded memory: Init(max_points) allocates the index and node arrays
// once; Build and every query allocate nothing. Leaves hold up to 8 points, splits are at the
// median of the widest axis (nth_element in place), queries use a fixed-depth stack.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

#include "msgraphs/base/expected.hpp"

namespace msgraphs::core {

class KdTree {
 public:
  static constexpr std::size_t kMaxK = 64;

  /// Allocates for up to `max_points` points.
  void Init(std::size_t max_points);
  std::size_t capacity() const { return index_.size(); }

  /// Indexes `points` (kept by reference: they must outlive the tree's use). kCapacityExceeded
  /// beyond capacity; kInvalidArgument for a non-finite point (filter first).
  Status Build(std::span<const Eigen::Vector3f> points);
  std::size_t size() const { return points_.size(); }
  /// The indexed points' indices in leaf order: neighbours in space are neighbours here, so
  /// queries made in this order reuse the same nodes and points (the cache and the branches).
  std::span<const std::uint32_t> leaf_order() const { return {index_.data(), points_.size()}; }

  /// The up to k nearest points within sqrt(max_dist2), nearest first. Returns how many were
  /// written to `indices`/`dist2` (both at least k long, k <= kMaxK).
  std::size_t Knn(const Eigen::Vector3f& query, std::size_t k, std::span<std::uint32_t> indices,
                  std::span<float> dist2, float max_dist2 = 3.4e38f) const;
  /// The nearest point; false when the tree is empty or none is within sqrt(max_dist2).
  bool Nearest(const Eigen::Vector3f& query, std::uint32_t& index, float& dist2, float max_dist2 = 3.4e38f) const;

 private:
  struct Node {
    float split = 0;
    std::uint32_t a = 0;  // inner: left child; leaf: first index
    std::uint32_t b = 0;  // inner: right child; leaf: one past the last index
    std::uint8_t axis = 3;  // 0..2: inner node split axis; 3: leaf
  };
  std::uint32_t BuildNode(std::uint32_t begin, std::uint32_t end, int depth);

  std::span<const Eigen::Vector3f> points_;
  std::vector<std::uint32_t> index_;
  std::vector<Node> nodes_;
  std::size_t node_count_ = 0;
};

}  // namespace msgraphs::core
