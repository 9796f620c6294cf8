// SPDX-License-Identifier: MIT
// The mapper's retention policy for its keyframe cloud store: what may go when the store is full.
//
// A place is a cell of a grid in the map frame (at the keyframes' current estimates). The
// newest `pinned` keyframes (the local map's) and the one being put are recent; the other
// stored clouds are settled. A stored cloud is
// - gone when its keyframe was sparsified or its slot reused;
// - pinned when its keyframe is recent: never evicted;
// - replaceable when a settled cloud shares its cell (the store asks oldest first, so the
//   newest settled cloud of a cell stays);
// - revisited when only recent clouds share its cell: the robot is back at that place. It
//   goes after every replaceable one: it is what a loop closure would verify against, and the
//   recent clouds are not candidates yet (they lie within the loop closer's path gap);
// - unique otherwise.
// So a long mission keeps a cloud of every place it mapped, not the last N keyframes': map.pcd
// and room descriptors see the whole building, and a loop can reach every place.
//
// The cell begins at the keyframe spacing (a walking robot leaves about one keyframe per cell;
// keyframes taken turning on the spot share one) and doubles whenever the other kinds cannot
// free the store's reclaim share (counted), up to the LiDAR's range (beyond it one cloud could
// not cover a cell); only then does a place lose its only cloud. Nothing allocates after Init.
#pragma once

#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "msgraphs/core/graph/s_graph.hpp"
#include "msgraphs/core/slam/keyframe_cloud_store.hpp"

namespace msgraphs {
class SnapshotReader;
class SnapshotWriter;
}  // namespace msgraphs

namespace msgraphs::core {

class CloudCoverPolicy final : public CloudRetentionPolicy {
 public:
  /// Its state in a snapshot (LocalMapper::Save / Load): the reader fails on a store of another
  /// size or a value out of range.
  void Save(SnapshotWriter& w) const;
  void Load(SnapshotReader& r);
  /// `slots`: keyframe ids are below it; `pinned`: the newest keyframes never evicted.
  void Init(std::size_t slots, std::size_t pinned, double first_cell_m, double max_cell_m);
  /// What the next Put judges against: the store, the graph, the keyframes' sequences and the
  /// keyframe whose cloud is being put.
  void Bind(const KeyframeCloudStore& store, const SGraph& graph,
            std::span<const std::uint64_t> sequences, std::uint32_t incoming);

  void BeginPass() override;
  CloudRetention Retention(std::uint32_t key, std::uint64_t sequence) const override;
  bool Coarsen() override;

  double cell_m() const { return cell_m_; }
  std::uint64_t coarsenings() const { return coarsenings_; }

 private:
  template <class Archive>
  void Io(Archive& ar);
  std::int64_t CellOf(std::uint32_t key) const;
  bool Recent(std::uint32_t key) const;

  const KeyframeCloudStore* store_ = nullptr;
  const SGraph* graph_ = nullptr;
  std::span<const std::uint64_t> sequences_;
  std::uint32_t incoming_ = 0;
  double cell_m_ = 1.0, max_cell_m_ = 1.0;
  std::uint64_t coarsenings_ = 0;
  // (cell, key) of the stored clouds and the incoming one, sorted, this pass
  std::vector<std::pair<std::int64_t, std::uint32_t>> cells_;
  std::size_t cell_count_ = 0;
  std::vector<std::int64_t> cell_of_;  // per key, this pass
  std::vector<std::uint32_t> pinned_;
  std::size_t pinned_count_ = 0;
};

}  // namespace msgraphs::core
