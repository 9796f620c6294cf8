// SPDX-License-Identifier: MIT
// Micro-benchmarks of the base vocabulary on the hot paths:
//   build/host-release/bench/msgraphs_base_bench
#include <benchmark/benchmark.h>

#include <array>
#include <cstdint>
#include <span>
#include <vector>
#if MSGRAPHS_BENCH_ZLIB
#include <zlib.h>
#endif

#include "msgraphs/base/bounded_vector.hpp"
#include "msgraphs/base/crc32.hpp"
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

// CRC-32 over a snapshot-sized buffer (an hour's map snapshot is 52 MB; a keyframe's journal
// record about 230 kB). Peers measured in the same run: the byte-at-a-time table msgraphs used
// before, and zlib's crc32 (the same CRC) where zlib is installed.
std::vector<std::uint8_t> Crc32Input(std::size_t bytes) {
  std::vector<std::uint8_t> data(bytes);
  for (std::size_t i = 0; i < data.size(); ++i) data[i] = static_cast<std::uint8_t>(i * 131 + 17);
  return data;
}

void BM_Crc32(benchmark::State& state) {
  const auto data = Crc32Input(static_cast<std::size_t>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(msgraphs::Crc32(data));
  state.SetBytesProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_Crc32)->Arg(230 << 10)->Arg(8 << 20);

std::uint32_t ByteAtATimeCrc32(std::span<const std::uint8_t> bytes) {
  static const auto table = [] {
    std::array<std::uint32_t, 256> t{};
    for (std::uint32_t i = 0; i < 256; ++i) {
      std::uint32_t c = i;
      for (int k = 0; k < 8; ++k) c = (c & 1u) != 0 ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      t[i] = c;
    }
    return t;
  }();
  std::uint32_t c = 0xFFFFFFFFu;
  for (std::uint8_t b : bytes) c = table[(c ^ b) & 0xFFu] ^ (c >> 8);
  return c ^ 0xFFFFFFFFu;
}

void BM_Crc32ByteAtATime(benchmark::State& state) {
  const auto data = Crc32Input(static_cast<std::size_t>(state.range(0)));
  if (ByteAtATimeCrc32(data) != msgraphs::Crc32(data)) state.SkipWithError("not the same CRC");
  for (auto _ : state) benchmark::DoNotOptimize(ByteAtATimeCrc32(data));
  state.SetBytesProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_Crc32ByteAtATime)->Arg(230 << 10)->Arg(8 << 20);

#if MSGRAPHS_BENCH_ZLIB
void BM_Crc32Zlib(benchmark::State& state) {
  const auto data = Crc32Input(static_cast<std::size_t>(state.range(0)));
  const auto zlib = [&] { return static_cast<std::uint32_t>(crc32(0L, data.data(), static_cast<uInt>(data.size()))); };
  if (zlib() != msgraphs::Crc32(data)) state.SkipWithError("not the same CRC");
  for (auto _ : state) benchmark::DoNotOptimize(zlib());
  state.SetBytesProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_Crc32Zlib)->Arg(230 << 10)->Arg(8 << 20);
#endif

}  // namespace
