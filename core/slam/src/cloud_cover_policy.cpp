// SPDX-License-Identifier: MIT
#include "msgraphs/core/slam/cloud_cover_policy.hpp"
#include "msgraphs/base/snapshot_archive.hpp"

#include <algorithm>
#include <cmath>

namespace msgraphs::core {
namespace {

// Three cell indices of 21 bits each in one key: +-2^20 cells is +-1,000 km at 1 m.
std::int64_t PackCell(double x, double y, double z) {
  constexpr double kHalf = 1 << 20;
  const auto part = [](double v) {
    if (!std::isfinite(v)) return std::int64_t{0};  // a pose the graph would refuse: one cell
    const double c = std::clamp(std::floor(v) + kHalf, 0.0, 2 * kHalf - 1);
    return static_cast<std::int64_t>(c);
  };
  return (part(x) << 42) | (part(y) << 21) | part(z);
}

}  // namespace

void CloudCoverPolicy::Init(std::size_t slots, std::size_t pinned, double first_cell_m, double max_cell_m) {
  cells_.assign(slots, {0, 0});
  cell_of_.assign(slots, 0);
  pinned_.assign(pinned, 0);
  cell_m_ = first_cell_m;
  max_cell_m_ = std::max(first_cell_m, max_cell_m);
  coarsenings_ = 0;
  cell_count_ = pinned_count_ = 0;
}

void CloudCoverPolicy::Bind(const KeyframeCloudStore& store, const SGraph& graph,
                            std::span<const std::uint64_t> sequences, std::uint32_t incoming) {
  store_ = &store;
  graph_ = &graph;
  sequences_ = sequences;
  incoming_ = incoming;
}

std::int64_t CloudCoverPolicy::CellOf(std::uint32_t key) const {
  const Eigen::Vector3d p = graph_->keyframe_pose(key).translation();
  // Height in half-cell-shifted steps: the base rides at a near-constant height on one floor, so
  // a boundary half a cell away from it never splits a floor's keyframes by noise.
  return PackCell(p.x() / cell_m_, p.y() / cell_m_, p.z() / cell_m_ + 0.5);
}

bool CloudCoverPolicy::Recent(std::uint32_t key) const {
  const auto pinned_end = pinned_.begin() + static_cast<std::ptrdiff_t>(pinned_count_);
  return key == incoming_ || std::find(pinned_.begin(), pinned_end, key) != pinned_end;
}

void CloudCoverPolicy::BeginPass() {
  cell_count_ = 0;
  pinned_count_ = 0;
  if (store_ == nullptr || graph_ == nullptr) return;
  pinned_count_ = graph_->RecentKeyframes(std::span(pinned_));
  const std::size_t slots = std::min({graph_->keyframe_slots(), sequences_.size(), cells_.size()});
  for (std::uint32_t k = 0; k < slots; ++k) {
    if (!graph_->keyframe_active(k)) continue;
    if (k != incoming_ && store_->Get(k, sequences_[k]).empty()) continue;
    cell_of_[k] = CellOf(k);
    cells_[cell_count_++] = {cell_of_[k], k};
  }
  std::sort(cells_.begin(), cells_.begin() + static_cast<std::ptrdiff_t>(cell_count_));
}

CloudRetention CloudCoverPolicy::Retention(std::uint32_t key, std::uint64_t sequence) const {
  if (store_ == nullptr || graph_ == nullptr) return CloudRetention::kReplaceable;
  // A slot reused by a newer keyframe, or a keyframe sparsified away: nothing shows this cloud.
  if (key >= sequences_.size() || key >= graph_->keyframe_slots() || key >= cell_of_.size() ||
      sequences_[key] != sequence || !graph_->keyframe_active(key)) {
    return CloudRetention::kGone;
  }
  if (Recent(key)) return CloudRetention::kPinned;
  const std::int64_t cell = cell_of_[key];
  const auto end = cells_.begin() + static_cast<std::ptrdiff_t>(cell_count_);
  bool recent_company = false;
  for (auto it = std::lower_bound(cells_.begin(), end, std::pair<std::int64_t, std::uint32_t>{cell, 0});
       it != end && it->first == cell; ++it) {
    const std::uint32_t other = it->second;
    if (other == key) continue;
    if (Recent(other)) {
      recent_company = true;  // pinned ones are stored; the incoming one is about to be
    } else if (!store_->Get(other, sequences_[other]).empty()) {
      // A settled cloud still stored (one evicted earlier in this pass is not) covers it.
      return CloudRetention::kReplaceable;
    }
  }
  return recent_company ? CloudRetention::kRevisited : CloudRetention::kUnique;
}

bool CloudCoverPolicy::Coarsen() {
  if (2 * cell_m_ > max_cell_m_) return false;
  cell_m_ *= 2;
  ++coarsenings_;
  return true;
}


// Only the cell size persists; the cells and the pinned keyframes are taken afresh each pass,
// and what the policy judges against is bound again before each Put.
// The cell is the first (Init's) doubled once per coarsening, up to the config's largest.
template <class Archive>
void CloudCoverPolicy::Io(Archive& ar) {
  if constexpr (!Archive::kLoading) {
    ar(coarsenings_);
  } else {
    const double first_cell_m = std::ldexp(cell_m_, -static_cast<int>(std::min<std::uint64_t>(coarsenings_, 64)));
    ar(coarsenings_);
    double cell_m = first_cell_m;
    for (std::uint64_t i = 0; i < coarsenings_ && i < 64; ++i) cell_m *= 2;
    if (coarsenings_ >= 64 || cell_m > max_cell_m_) {
      ar.Fail();
      coarsenings_ = 0;
      cell_m = first_cell_m;
    }
    cell_m_ = cell_m;
  }
}

void CloudCoverPolicy::Save(SnapshotWriter& w) const { const_cast<CloudCoverPolicy*>(this)->Io(w); }
void CloudCoverPolicy::Load(SnapshotReader& r) { Io(r); }

}  // namespace msgraphs::core
