// SPDX-License-Identifier: MIT
// Which factor slot a Ceres residual block belongs to (core_graph only).
//
// Ceres names a residual block by its address, and hands a parameter block's residual blocks
// back in hash-set order. A solve that took them in either order would depend on where the heap
// put them: two graphs with the same records (a live one and one rebuilt from a snapshot, or a
// journal replay) would round differently, and a replay would no longer be exact. So every
// problem the graph hands Ceres lists its residual blocks by factor slot, a number the graph
// itself chose; this index gives the slot of a block in O(1) without a scan of the factors.
//
// Open addressing with linear probing and backward-shift deletion, sized at Init (twice the
// factor store, a power of two): Insert, Erase and Find allocate nothing.
#pragma once

#include <ceres/ceres.h>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace msgraphs::core::sgraph {

class ResidualIndex {
 public:
  static constexpr std::int32_t kAbsent = -1;

  // Room for max_entries blocks at a load of at most one half.
  void Init(std::size_t max_entries) {
    std::size_t capacity = 16;
    while (capacity < 2 * max_entries) capacity *= 2;
    table_.assign(capacity, Entry{});
    mask_ = capacity - 1;
    size_ = 0;
  }
  void Clear() {
    for (Entry& e : table_) e = Entry{};
    size_ = 0;
  }
  std::size_t size() const { return size_; }

  // False when the store is full (more blocks than Init allowed for) or the block is listed.
  bool Insert(ceres::ResidualBlockId id, std::int32_t slot) {
    if (id == nullptr || 2 * (size_ + 1) > table_.size()) return false;
    for (std::size_t i = Home(id);; i = (i + 1) & mask_) {
      if (table_[i].id == id) return false;
      if (table_[i].id != nullptr) continue;
      table_[i] = Entry{id, slot};
      ++size_;
      return true;
    }
  }

  // Forgets the block if it is listed under `slot`: a block Ceres freed may come back at the
  // same address for another factor before the first one's record is dropped.
  void Erase(ceres::ResidualBlockId id, std::int32_t slot) {
    if (id == nullptr || table_.empty()) return;
    std::size_t i = Home(id);
    while (table_[i].id != id) {
      if (table_[i].id == nullptr) return;
      i = (i + 1) & mask_;
    }
    if (table_[i].slot != slot) return;
    // Backward shift: every later entry of the run that may sit at i moves there.
    for (std::size_t j = (i + 1) & mask_;; j = (j + 1) & mask_) {
      if (table_[j].id == nullptr) break;
      const std::size_t home = Home(table_[j].id);
      // Entry j may move to i when its home does not lie in the cyclic range (i, j].
      const bool stays = i <= j ? (home > i && home <= j) : (home > i || home <= j);
      if (stays) continue;
      table_[i] = table_[j];
      i = j;
    }
    table_[i] = Entry{};
    --size_;
  }

  std::int32_t Find(ceres::ResidualBlockId id) const {
    if (id == nullptr || table_.empty()) return kAbsent;
    for (std::size_t i = Home(id);; i = (i + 1) & mask_) {
      if (table_[i].id == id) return table_[i].slot;
      if (table_[i].id == nullptr) return kAbsent;
    }
  }

  std::size_t bytes() const { return table_.capacity() * sizeof(Entry); }

 private:
  struct Entry {
    ceres::ResidualBlockId id = nullptr;
    std::int32_t slot = kAbsent;
  };
  std::size_t Home(ceres::ResidualBlockId id) const {
    // Fibonacci hashing of the address (its low bits are alignment).
    const auto a = static_cast<std::uint64_t>(reinterpret_cast<std::uintptr_t>(id));
    return static_cast<std::size_t>((a * 0x9E3779B97F4A7C15ull) >> 20) & mask_;
  }
  std::vector<Entry> table_;
  std::size_t mask_ = 0, size_ = 0;
};

}  // namespace msgraphs::core::sgraph
