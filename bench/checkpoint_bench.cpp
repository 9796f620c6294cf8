// SPDX-License-Identifier: MIT
// What a checkpoint snapshot costs, on the mapper of a real long mission: the SLAM thread's
// Save (sealed at once, or the copy alone with the CRCs left to the writer thread), the writer
// thread's SealSnapshot, and a restart's Load. The mission is a checkpoint folder's snapshot
// file and the node config that made it (tools/eval/restart_eval.sh writes both):
//   MSGRAPHS_BENCH_NODE_CONFIG=OUT/robot.conf
//   MSGRAPHS_BENCH_SNAPSHOT=OUT/generations/checkpoint/snapshot.N.bin
//   build/host-release/bench/msgraphs_checkpoint_bench
// Without them every benchmark reports itself skipped, with the reason.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>
#include <span>
#include <vector>

#include "msgraphs/core/slam/local_mapper.hpp"
#include "msgraphs/runtime/config/node_config.hpp"
#include "msgraphs/runtime/pipeline/checkpoint_file.hpp"

namespace {

using msgraphs::SnapshotSeal;
using msgraphs::core::LocalMapper;

// The mission's mapper, loaded once; `why` says what is missing when it is not.
struct Mission {
  msgraphs::runtime::config::NodeConfig config;
  std::vector<std::uint8_t> mapper_bytes;  ///< LocalMapper::Load's bytes, as the file holds them
  std::unique_ptr<LocalMapper> mapper;
  std::string why;
};

Mission& TheMission() {
  static Mission m = [] {
    Mission out;
    const char* config_path = std::getenv("MSGRAPHS_BENCH_NODE_CONFIG");
    const char* snapshot_path = std::getenv("MSGRAPHS_BENCH_SNAPSHOT");
    if (config_path == nullptr || snapshot_path == nullptr) {
      out.why = "set MSGRAPHS_BENCH_NODE_CONFIG and MSGRAPHS_BENCH_SNAPSHOT (tools/eval/restart_eval.sh writes both)";
      return out;
    }
    std::string error;
    if (!msgraphs::runtime::config::LoadNodeConfig(config_path, {}, out.config, error)) {
      out.why = error;
      return out;
    }
    std::ifstream file(snapshot_path, std::ios::binary);
    const std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(file)), {});
    auto parsed = msgraphs::runtime::ParseCheckpoint(bytes, out.config.robot.value);
    if (!parsed) {
      out.why = std::string(snapshot_path) + ": " + std::string(parsed.error().detail);
      return out;
    }
    out.mapper_bytes.assign(parsed->mapper.begin(), parsed->mapper.end());
    out.mapper = std::make_unique<LocalMapper>();
    if (auto s = out.mapper->Init(out.config.mapper); !s) {
      out.why = std::string("mapper Init: ") + s.error().detail;
      return out;
    }
    if (auto s = out.mapper->Load(out.mapper_bytes); !s) {
      out.why = std::string("mapper Load: ") + s.error().detail;
      return out;
    }
    // Load begins the full solve the snapshot wanted; a save waits for it to be applied.
    if (auto s = out.mapper->Finish(); !s) out.why = std::string("mapper Finish: ") + s.error().detail;
    return out;
  }();
  return m;
}

// The buffer is written before (warm: the node's snapshots after its first, the buffer's pages
// already there) or fresh each time (cold: the node's first snapshot, which faults the pages in;
// the node allocates the buffer unwritten).
void BM_MapperSave(benchmark::State& state) {
  Mission& m = TheMission();
  if (!m.why.empty()) return state.SkipWithError(m.why.c_str());
  const auto seal = state.range(0) == 0 ? SnapshotSeal::kNow : SnapshotSeal::kLater;
  const bool cold = state.range(1) != 0;
  const std::size_t capacity = m.mapper->SnapshotBytes();
  std::unique_ptr<std::uint8_t[]> out(new std::uint8_t[capacity]);
  if (!cold) std::fill_n(out.get(), capacity, std::uint8_t{0});
  std::size_t bytes = 0;
  for (auto _ : state) {
    if (cold) {
      state.PauseTiming();
      out.reset();
      out.reset(new std::uint8_t[capacity]);  // unwritten: its pages come at the first write
      state.ResumeTiming();
    }
    auto n = m.mapper->Save(std::span(out.get(), capacity), seal);
    if (!n) return state.SkipWithError(n.error().detail);
    bytes = *n;
  }
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(bytes));
  state.counters["snapshot_MB"] = static_cast<double>(bytes) / 1e6;
}
// 0: sealed at once (one thread pays for copy and CRCs); 1: the copy, sealed later (the node's
// SLAM thread).
BENCHMARK(BM_MapperSave)
    ->ArgNames({"sealed_later", "cold"})
    ->Args({0, 0})
    ->Args({1, 0})
    ->Args({1, 1})
    ->Unit(benchmark::kMillisecond);

void BM_MapperSealSnapshot(benchmark::State& state) {
  Mission& m = TheMission();
  if (!m.why.empty()) return state.SkipWithError(m.why.c_str());
  std::vector<std::uint8_t> out(m.mapper->SnapshotBytes());
  auto n = m.mapper->Save(out, SnapshotSeal::kLater);
  if (!n) return state.SkipWithError(n.error().detail);
  const std::span<std::uint8_t> snapshot(out.data(), *n);
  for (auto _ : state) {
    if (!LocalMapper::SealSnapshot(snapshot)) return state.SkipWithError("seal refused");
  }
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(*n));
}
BENCHMARK(BM_MapperSealSnapshot)->Unit(benchmark::kMillisecond);

// A restart's load: into a mapper just initialised, as the node's is (Init outside the timing).
void BM_MapperLoad(benchmark::State& state) {
  Mission& m = TheMission();
  if (!m.why.empty()) return state.SkipWithError(m.why.c_str());
  for (auto _ : state) {
    state.PauseTiming();
    auto mapper = std::make_unique<LocalMapper>();
    if (!mapper->Init(m.config.mapper)) return state.SkipWithError("mapper Init");
    state.ResumeTiming();
    if (auto s = mapper->Load(m.mapper_bytes); !s) return state.SkipWithError(s.error().detail);
    state.PauseTiming();
    static_cast<void>(mapper->Finish());  // the solve Load began, outside the timing
    mapper.reset();
    state.ResumeTiming();
  }
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(m.mapper_bytes.size()));
}
BENCHMARK(BM_MapperLoad)->Unit(benchmark::kMillisecond)->Iterations(5);

}  // namespace
