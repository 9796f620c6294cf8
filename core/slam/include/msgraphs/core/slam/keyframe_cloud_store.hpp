// SPDX-License-Identifier: MIT
// Downsampled keyframe clouds (base frame) for the local map, loop-closure verification, room
// descriptors and the exported map, in one block of points sized at Init.
//
// Clouds are appended in the order they are put. When a new one does not fit, the store makes
// room, oldest first, by what a retention policy (the mapper's) says of each stored cloud (see
// CloudRetention), in this order: gone and replaceable clouds, then revisited ones, up to
// `reclaim_points` (Init); short of that, the policy is asked to make its places coarser and
// the passes run again; only then do unique clouds go, as many as the new cloud needs. Pinned
// clouds never go. Without a policy the oldest go, as a ring would. The survivors are then slid
// down over the freed space in order (one memmove of what is stored): freeing `reclaim_points`
// at a time pays the slide once per that many points put, except when only unique clouds are
// left to go. Nothing allocates after Init
// (KeyframeCloudStore.PuttingAndGettingAllocateNothingAfterInit).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

#include "msgraphs/base/expected.hpp"

namespace msgraphs {
class SnapshotReader;
class SnapshotWriter;
}  // namespace msgraphs

namespace msgraphs::core {

/// What making room may do with one stored cloud.
enum class CloudRetention : std::uint8_t {
  kGone,         ///< nothing shows it any more (its keyframe was sparsified, its slot reused)
  kReplaceable,  ///< another stored cloud, an older settled one, covers its place
  kRevisited,    ///< only recent clouds (pinned, or the one being put) share its place
  kUnique,       ///< the only cloud of its place: kept while any other kind can go
  kPinned,       ///< needed now (e.g. the local map's keyframes): never evicted to make room
};

/// Asked by Put about the stored clouds, oldest first, while it makes room. It may call the
/// store's Get: a cloud evicted earlier in the same pass is already gone, so two clouds that
/// cover each other are never both evicted for it.
class CloudRetentionPolicy {
 public:
  /// A pass begins: the stored clouds are those Get returns now.
  virtual void BeginPass() {}
  virtual CloudRetention Retention(std::uint32_t key, std::uint64_t sequence) const = 0;
  /// Gone, replaceable and revisited clouds did not free `reclaim_points`: make places coarser
  /// and say so (the passes run again), or return false (unique clouds then go, oldest first, as
  /// many as the new cloud needs). Must return false after finitely many calls.
  virtual bool Coarsen() { return false; }

 protected:
  ~CloudRetentionPolicy() = default;
};

struct KeyframeCloudStoreStats {
  std::uint64_t evicted = 0;            ///< all clouds evicted to make room
  std::uint64_t evicted_gone = 0;       ///< of them, with a policy: their keyframe was gone
  std::uint64_t evicted_covered = 0;    ///< replaceable or revisited (the place keeps a cloud)
  std::uint64_t evicted_uncovered = 0;  ///< unique: a place left without a cloud (until revisited)
  std::uint64_t compactions = 0;        ///< passes that slid the survivors down
  std::uint64_t refused = 0;  ///< Puts refused: only pinned clouds left, or larger than the store
};

class KeyframeCloudStore {
 public:
  /// Its state in a snapshot (LocalMapper::Save / Load): the reader fails on a store of another
  /// size or a value out of range.
  void Save(SnapshotWriter& w) const;
  void Load(SnapshotReader& r);
  /// `max_keys`: keyframe ids are below it; `max_points`: the block; `reclaim_points`: the
  /// least a pass frees (0: what the new cloud needs; at most max_points).
  void Init(std::size_t max_keys, std::size_t max_points, std::size_t reclaim_points = 0);

  /// Stores (replacing what `key` held: a refused Put leaves the key without a cloud). `sequence`
  /// tells a reused key from its previous owner. `policy` (may be null: the oldest go) decides
  /// what making room may evict.
  Status Put(std::uint32_t key, std::uint64_t sequence, std::span<const Eigen::Vector3f> points,
             CloudRetentionPolicy* policy = nullptr);
  /// The cloud, or an empty span when it was evicted or never stored.
  std::span<const Eigen::Vector3f> Get(std::uint32_t key, std::uint64_t sequence) const;

  std::size_t used_points() const { return used_; }
  std::size_t peak_points() const { return peak_; }
  std::size_t capacity_points() const { return points_.size(); }
  std::size_t stored_clouds() const { return live_; }
  std::uint64_t evicted() const { return stats_.evicted; }
  const KeyframeCloudStoreStats& stats() const { return stats_; }

 private:
  template <class Archive>
  void Io(Archive& ar);
  struct Entry {
    std::size_t offset = 0, count = 0;
    std::uint64_t sequence = 0;
    std::uint64_t stamp = 0;  // the store's count of Puts when it was put
    bool valid = false;
  };
  bool Live(std::size_t order_index) const;
  bool Consistent() const;  // a loaded snapshot's entries hold together (snapshot Load)
  void Evict(std::uint32_t key, const CloudRetentionPolicy* policy, CloudRetention why);
  /// Evicts, oldest first, until `need` points are free at the top (after sliding).
  void MakeRoom(std::size_t need, CloudRetentionPolicy* policy);
  /// One pass, oldest first: evicts the clouds of the kinds `take` accepts until `goal` is free.
  template <typename Take>
  void EvictPass(std::size_t goal, CloudRetentionPolicy* policy, Take take);
  /// Slides the live clouds down in order over the freed space; drops stale order entries.
  void Compact();

  std::vector<Eigen::Vector3f> points_;
  std::vector<Entry> entries_;
  // Keys in the order their clouds lie in points_ (oldest first), with the stamp each was put
  // with: an entry whose key was replaced or evicted since is stale and skipped.
  std::vector<std::uint32_t> order_;
  std::vector<std::uint64_t> order_stamp_;
  std::uint64_t stamp_ = 0;
  std::size_t order_size_ = 0;
  std::size_t top_ = 0;  // points_[top_, size) is free
  std::size_t used_ = 0, peak_ = 0, live_ = 0, reclaim_ = 0;
  KeyframeCloudStoreStats stats_;
};

}  // namespace msgraphs::core
