// SPDX-License-Identifier: MIT
#include "msgraphs/core/perception/kdtree.hpp"

#include <algorithm>
#include <cmath>

namespace msgraphs::core {
namespace {
constexpr std::uint32_t kLeafSize = 8;
constexpr int kMaxDepth = 64;
}  // namespace

void KdTree::Init(std::size_t max_points) {
  index_.assign(max_points, 0);
  // Leaves hold at least kLeafSize / 2 points, so there are at most 2 n / kLeafSize + 1 of them
  // and fewer inner nodes than leaves.
  nodes_.assign(4 * max_points / kLeafSize + 8, Node{});
  points_ = {};
  node_count_ = 0;
}

Status KdTree::Build(std::span<const Eigen::Vector3f> points) {
  points_ = {};
  node_count_ = 0;
  if (points.size() > index_.size()) return Error{Errc::kCapacityExceeded, "kdtree: more points than Init allowed"};
  for (const auto& p : points) {
    if (!p.allFinite()) return Error{Errc::kInvalidArgument, "kdtree: non-finite point"};
  }
  points_ = points;
  for (std::uint32_t i = 0; i < points.size(); ++i) index_[i] = i;
  if (!points.empty()) BuildNode(0, static_cast<std::uint32_t>(points.size()), 0);
  return Ok();
}

std::uint32_t KdTree::BuildNode(std::uint32_t begin, std::uint32_t end, int depth) {
  const auto id = static_cast<std::uint32_t>(node_count_++);
  MSGRAPHS_ASSERT(node_count_ <= nodes_.size(), "kdtree: node bound violated");
  if (end - begin <= kLeafSize || depth >= kMaxDepth - 2) {
    nodes_[id] = {0.0f, begin, end, 3};
    return id;
  }
  Eigen::Vector3f lo = points_[index_[begin]], hi = lo;
  for (std::uint32_t i = begin + 1; i < end; ++i) {
    lo = lo.cwiseMin(points_[index_[i]]);
    hi = hi.cwiseMax(points_[index_[i]]);
  }
  int axis = 0;
  (hi - lo).maxCoeff(&axis);
  if (hi[axis] - lo[axis] <= 0.0f) {  // all points identical: one leaf, whatever its size
    nodes_[id] = {0.0f, begin, end, 3};
    return id;
  }
  const std::uint32_t mid = begin + (end - begin) / 2;
  std::nth_element(index_.begin() + begin, index_.begin() + mid, index_.begin() + end,
                   [&](std::uint32_t x, std::uint32_t y) { return points_[x][axis] < points_[y][axis]; });
  const float split = points_[index_[mid]][axis];
  const std::uint32_t left = BuildNode(begin, mid, depth + 1);
  const std::uint32_t right = BuildNode(mid, end, depth + 1);
  nodes_[id] = {split, left, right, static_cast<std::uint8_t>(axis)};
  return id;
}

std::size_t KdTree::Knn(const Eigen::Vector3f& q, std::size_t k, std::span<std::uint32_t> indices,
                        std::span<float> dist2, float max_dist2) const {
  k = std::min({k, kMaxK, indices.size(), dist2.size()});
  if (points_.empty() || k == 0) return 0;
  std::size_t found = 0;
  float worst = max_dist2;  // the k-th best so far once full, else the radius
  struct Item {
    std::uint32_t node;
    float bound;  // squared distance from q to the node's half-space
  };
  Item stack[kMaxDepth * 2];
  int top = 0;
  stack[top++] = {0, 0.0f};
  while (top > 0) {
    const Item item = stack[--top];
    if (item.bound > worst) continue;
    const Node& n = nodes_[item.node];
    if (n.axis == 3) {
      for (std::uint32_t i = n.a; i < n.b; ++i) {
        const std::uint32_t idx = index_[i];
        const float d = (points_[idx] - q).squaredNorm();
        if (d > worst || (found == k && d >= dist2[k - 1])) continue;
        // Insertion into the sorted result.
        std::size_t pos = found < k ? found++ : k - 1;
        while (pos > 0 && dist2[pos - 1] > d) {
          dist2[pos] = dist2[pos - 1];
          indices[pos] = indices[pos - 1];
          --pos;
        }
        dist2[pos] = d;
        indices[pos] = idx;
        if (found == k) worst = std::min(worst, dist2[k - 1]);
      }
      continue;
    }
    const float diff = q[n.axis] - n.split;
    const std::uint32_t near = diff < 0 ? n.a : n.b;
    const std::uint32_t far = diff < 0 ? n.b : n.a;
    // The far side lies inside this node's region and beyond the split plane: both distances
    // bound it from below, and the larger prunes more.
    stack[top++] = {far, std::max(item.bound, diff * diff)};  // visited after the near side
    stack[top++] = {near, item.bound};
  }
  return found;
}

bool KdTree::Nearest(const Eigen::Vector3f& q, std::uint32_t& index, float& dist2, float max_dist2) const {
  std::uint32_t i[1];
  float d[1];
  if (Knn(q, 1, i, d, max_dist2) == 0) return false;
  index = i[0];
  dist2 = d[0];
  return true;
}

}  // namespace msgraphs::core
