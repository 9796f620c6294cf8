// SPDX-License-Identifier: MIT
// The front end's stores: what a keyframe pays to put its cloud into a full cloud store (making
// room and sliding the survivors down, amortised over the Puts between passes).
//   build/host-release/bench/msgraphs_slam_bench
#include <benchmark/benchmark.h>

#include <cstdint>
#include <vector>

#include "msgraphs/core/slam/keyframe_cloud_store.hpp"

namespace {

using msgraphs::core::CloudRetention;
using msgraphs::core::CloudRetentionPolicy;
using msgraphs::core::KeyframeCloudStore;

// A patrol of 128 places walked over and over (key k is place k % 128): every older cloud of a
// place is covered by its newer visit.
class PatrolPolicy final : public CloudRetentionPolicy {
 public:
  static constexpr std::uint32_t kPlaces = 128;
  PatrolPolicy(const KeyframeCloudStore& store, const std::vector<std::uint64_t>& sequence)
      : store_(store), sequence_(sequence) {}
  CloudRetention Retention(std::uint32_t key, std::uint64_t) const override {
    for (auto other = key % kPlaces; other < sequence_.size(); other += kPlaces) {
      if (other != key && !store_.Get(other, sequence_[other]).empty()) return CloudRetention::kReplaceable;
    }
    return CloudRetention::kUnique;
  }

 private:
  const KeyframeCloudStore& store_;
  const std::vector<std::uint64_t>& sequence_;
};

// Every cloud its place's only one: each Put evicts one unique cloud and slides the store.
class AllUniquePolicy final : public CloudRetentionPolicy {
 public:
  CloudRetention Retention(std::uint32_t, std::uint64_t) const override { return CloudRetention::kUnique; }
};

// The node's store (1.5 M points, a sixteenth reclaimed per pass) with clouds of state.range(0)
// points, full; arg 1: 0 without a policy (the oldest go), 1 a patrol (older visits covered),
// 2 every cloud unique (the worst case: a building larger than the store at its coarsest).
void BM_CloudStorePutWhenFull(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  const std::int64_t mode = state.range(1);
  constexpr std::size_t kKeys = 4096, kPoints = 1500000;  // a multiple of the patrol's places
  KeyframeCloudStore store;
  store.Init(kKeys, kPoints, kPoints / 16);
  std::vector<std::uint64_t> sequence(kKeys, 0);
  PatrolPolicy patrol(store, sequence);
  AllUniquePolicy unique;
  CloudRetentionPolicy* policy = mode == 1 ? static_cast<CloudRetentionPolicy*>(&patrol)
                                 : mode == 2 ? static_cast<CloudRetentionPolicy*>(&unique)
                                             : nullptr;
  const std::vector<Eigen::Vector3f> cloud(n, Eigen::Vector3f(1, 2, 3));
  std::uint64_t put = 0;
  const auto next = [&]() {
    const auto key = static_cast<std::uint32_t>(put % kKeys);
    sequence[key] = ++put;
    return store.Put(key, sequence[key], cloud, policy);
  };
  while (store.used_points() + n <= kPoints) static_cast<void>(next());  // full
  for (auto _ : state) benchmark::DoNotOptimize(next());
  state.counters["compactions"] = static_cast<double>(store.stats().compactions);
  state.counters["evicted"] = static_cast<double>(store.evicted());
}
BENCHMARK(BM_CloudStorePutWhenFull)->Args({6000, 0})->Args({6000, 1})->Args({6000, 2})->Unit(benchmark::kMicrosecond);

}  // namespace
