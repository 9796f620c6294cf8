// SPDX-License-Identifier: MIT
// Micro-benchmarks of the base vocabulary on the hot paths:
//   build/host-release/bench/msgraphs_base_bench
#include <benchmark/benchmark.h>

#include <array>

#include "msgraphs/base/bounded_vector.hpp"
#include "msgraphs/base/ring_buffer.hpp"
#include "msgraphs/core/geometry/se3.hpp"
#include "msgraphs/drivers/can_odometry/crc8.hpp"

namespace {

void BM_RingBufferPushPop(benchmark::State& state) {
  msgraphs::RingBuffer<std::array<float, 4>, 1024> rb(msgraphs::OverflowPolicy::kDropOldest);
  std::array<float, 4> item{1.0F, 2.0F, 3.0F, 4.0F};
  for (auto _ : state) {
    static_cast<void>(rb.push(item));
    auto out = rb.pop();
    benchmark::DoNotOptimize(out);
  }
}
BENCHMARK(BM_RingBufferPushPop);

// One VLP-16 rotation is about 28,800 points at 10 Hz: the cost of filling a scan buffer.
void BM_BoundedVectorFillScan(benchmark::State& state) {
  msgraphs::BoundedVector<std::array<float, 4>> scan(32768);
  for (auto _ : state) {
    scan.clear();
    for (int i = 0; i < 28800; ++i) {
      static_cast<void>(scan.try_push_back({static_cast<float>(i), 0.0F, 0.0F, 1.0F}));
    }
    benchmark::DoNotOptimize(scan.data());
  }
  state.SetItemsProcessed(state.iterations() * 28800);
}
BENCHMARK(BM_BoundedVectorFillScan);

void BM_Se3ExpLog(benchmark::State& state) {
  msgraphs::core::Vector6d xi;
  xi << 0.1, -0.2, 0.3, 0.01, 0.5, -0.2;
  for (auto _ : state) {
    const Eigen::Isometry3d T = msgraphs::core::Se3Exp(xi);
    xi = msgraphs::core::Se3Log(T);
    benchmark::DoNotOptimize(xi);
  }
}
BENCHMARK(BM_Se3ExpLog);

void BM_Crc8CanFrame(benchmark::State& state) {
  std::array<std::uint8_t, 7> frame{0x10, 0x27, 0xF0, 0xD8, 0x64, 0x00, 0x2A};
  for (auto _ : state) {
    benchmark::DoNotOptimize(msgraphs::drivers::can_odometry::Crc8SaeJ1850(frame));
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_Crc8CanFrame);

}  // namespace
