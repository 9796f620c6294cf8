// SPDX-License-Identifier: MIT
// A bounded store of Scan Context descriptors (room descriptors received from the fleet) with
// nearest-neighbour search on the ring keys followed by the full column-shift distance on the
// best candidates. Capacity is fixed at Init. When full, adding a new id is refused
// (kCapacityExceeded, counted in `rejected()`); updating an existing id always works.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "msgraphs/base/expected.hpp"
#include "msgraphs/core/descriptors/scan_context.hpp"

namespace msgraphs::core {

struct ScanContextCandidate {
  std::uint64_t id = 0;
  float ring_key_distance = 0.0f;
  ScanContextMatch match;
};

class ScanContextDatabase {
 public:
  static constexpr std::size_t kMaxCandidates = 32;

  void Init(std::size_t capacity, int rings, int sectors);

  /// Inserts or replaces the descriptor stored under `id`.
  Status Upsert(std::uint64_t id, const ScanContext& descriptor);
  bool Remove(std::uint64_t id);

  /// The `candidates` nearest entries by ring key, re-ranked by Scan Context distance (best
  /// first). Each match's yaw maps the stored descriptor's frame into the query's frame
  /// (p_query = Rz(yaw) p_stored). Writes at most out.size() results; returns how many.
  std::size_t Query(const ScanContext& query, std::size_t candidates, std::span<ScanContextCandidate> out,
                    bool search_all_shifts = false) const;

  std::size_t size() const { return size_; }
  std::size_t capacity() const { return ids_.size(); }
  std::size_t peak() const { return peak_; }
  std::uint64_t rejected() const { return rejected_; }

 private:
  int rings_ = 0, sectors_ = 0;
  std::size_t size_ = 0, peak_ = 0;
  std::uint64_t rejected_ = 0;
  std::vector<std::uint64_t> ids_;
  std::vector<float> ring_keys_;  // size_ x rings_, contiguous for the linear scan
  std::vector<ScanContext> descriptors_;
};

}  // namespace msgraphs::core
