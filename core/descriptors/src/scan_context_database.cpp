// SPDX-License-Identifier: MIT
#include "msgraphs/core/descriptors/scan_context_database.hpp"

#include <algorithm>
#include <cmath>

namespace msgraphs::core {

void ScanContextDatabase::Init(std::size_t capacity, int rings, int sectors) {
  rings_ = rings;
  sectors_ = sectors;
  ids_.assign(capacity, 0);
  ring_keys_.assign(capacity * static_cast<std::size_t>(std::max(rings, 1)), 0.0f);
  descriptors_.assign(capacity, ScanContext{});
  size_ = peak_ = 0;
  rejected_ = 0;
}

Status ScanContextDatabase::Upsert(std::uint64_t id, const ScanContext& d) {
  if (d.rings() != rings_ || d.sectors() != sectors_) return Error{Errc::kInvalidArgument, "scan context db: descriptor size differs"};
  std::size_t slot = size_;
  for (std::size_t i = 0; i < size_; ++i) {
    if (ids_[i] == id) {
      slot = i;
      break;
    }
  }
  if (slot == size_) {
    if (size_ == ids_.size()) {
      ++rejected_;
      return Error{Errc::kCapacityExceeded, "scan context db: full"};
    }
    ++size_;
    peak_ = std::max(peak_, size_);
  }
  ids_[slot] = id;
  descriptors_[slot] = d;
  for (int r = 0; r < rings_; ++r) ring_keys_[slot * static_cast<std::size_t>(rings_) + static_cast<std::size_t>(r)] = d.ring_key(r);
  return Ok();
}

bool ScanContextDatabase::Remove(std::uint64_t id) {
  for (std::size_t i = 0; i < size_; ++i) {
    if (ids_[i] != id) continue;
    const std::size_t last = size_ - 1;  // move the last entry into the hole
    ids_[i] = ids_[last];
    descriptors_[i] = descriptors_[last];
    std::copy_n(ring_keys_.begin() + static_cast<std::ptrdiff_t>(last * static_cast<std::size_t>(rings_)), rings_,
                ring_keys_.begin() + static_cast<std::ptrdiff_t>(i * static_cast<std::size_t>(rings_)));
    --size_;
    return true;
  }
  return false;
}

std::size_t ScanContextDatabase::Query(const ScanContext& q, std::size_t candidates, std::span<ScanContextCandidate> out,
                                       bool search_all_shifts) const {
  if (q.rings() != rings_ || q.sectors() != sectors_ || size_ == 0) return 0;
  candidates = std::min({candidates, kMaxCandidates, size_});
  // Ring-key k nearest by a linear scan (a few hundred entries: faster than a tree rebuild).
  std::size_t best_index[kMaxCandidates];
  float best_d2[kMaxCandidates];
  std::size_t found = 0;
  for (std::size_t i = 0; i < size_; ++i) {
    const float* key = &ring_keys_[i * static_cast<std::size_t>(rings_)];
    float d2 = 0.0f;
    for (int r = 0; r < rings_; ++r) {
      const float e = key[r] - q.ring_key(r);
      d2 += e * e;
    }
    if (found == candidates && d2 >= best_d2[found - 1]) continue;
    std::size_t pos = found < candidates ? found++ : candidates - 1;
    while (pos > 0 && best_d2[pos - 1] > d2) {
      best_d2[pos] = best_d2[pos - 1];
      best_index[pos] = best_index[pos - 1];
      --pos;
    }
    best_d2[pos] = d2;
    best_index[pos] = i;
  }
  ScanContextCandidate ranked[kMaxCandidates];
  for (std::size_t k = 0; k < found; ++k) {
    ranked[k].id = ids_[best_index[k]];
    ranked[k].ring_key_distance = std::sqrt(best_d2[k]);
    ranked[k].match = ScanContextDistance(q, descriptors_[best_index[k]], search_all_shifts).value();
  }
  std::sort(ranked, ranked + found, [](const ScanContextCandidate& a, const ScanContextCandidate& b) {
    return a.match.distance < b.match.distance;
  });
  const std::size_t n = std::min(found, out.size());
  std::copy_n(ranked, n, out.begin());
  return n;
}

}  // namespace msgraphs::core
