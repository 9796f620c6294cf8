// SPDX-License-Identifier: MIT
// Every robot's view of every other, exchange after exchange: when robot A first had robot B
// merged (mission time of that exchange, on the lock-step clock), and every later change (a
// merge the session withdrew, and any merge after it).
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <optional>
#include <vector>

#include "mission.hpp"

namespace msgraphs::tools::collab {

struct MergeChange {
  double mission_time_s = 0;
  bool merged = false;
};

struct MergedEstimate {
  double mission_time_s = 0;
  Eigen::Isometry3d T_viewer_robot = Eigen::Isometry3d::Identity();
};

struct ViewHistory {
  std::optional<double> first_merge_s;  ///< the first exchange after which A had B merged
  std::vector<MergeChange> changes;     ///< every change of merged, in order
  /// A's estimate of B's origin after every exchange while merged (judged against the truth at
  /// the end: a merge that was wrong for a while counts, even if undone later).
  std::vector<MergedEstimate> estimates;
  std::size_t unmerges() const {
    std::size_t n = 0;
    for (const MergeChange& c : changes) n += c.merged ? 0 : 1;
    return n;
  }
};

class MergeTracker {
 public:
  explicit MergeTracker(std::size_t robots) : robots_(robots), views_(robots * robots) {}

  /// After an exchange at `mission_time_s`: every ordered pair's merged state.
  void AfterExchange(const Mission& mission, double mission_time_s) {
    for (const auto& a : mission.robots) {
      for (const auto& b : mission.robots) {
        if (a == b) continue;
        ViewHistory& h = at(a->index, b->index);
        const bool merged = mission.Merged(*a, b->index);
        if (merged) h.estimates.push_back({mission_time_s, mission.Origin(*a, b->index)});
        const bool was = !h.changes.empty() && h.changes.back().merged;
        if (merged == was) continue;
        h.changes.push_back({mission_time_s, merged});
        if (merged && !h.first_merge_s) h.first_merge_s = mission_time_s;
      }
    }
  }

  const ViewHistory& at(int viewer_index, int peer_index) const {
    return views_[static_cast<std::size_t>(viewer_index) * robots_ +
                  static_cast<std::size_t>(peer_index)];
  }

 private:
  ViewHistory& at(int viewer_index, int peer_index) {
    return views_[static_cast<std::size_t>(viewer_index) * robots_ +
                  static_cast<std::size_t>(peer_index)];
  }
  std::size_t robots_;
  std::vector<ViewHistory> views_;
};

}  // namespace msgraphs::tools::collab
