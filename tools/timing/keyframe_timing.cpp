// SPDX-License-Identifier: MIT
#include "msgraphs/tools/keyframe_timing.hpp"

#include <unistd.h>

#include <algorithm>

namespace msgraphs::tools {
namespace {

std::vector<double> Slice(const std::vector<double>& v, std::size_t first, std::size_t last) {
  return {v.begin() + static_cast<std::ptrdiff_t>(first),
          v.begin() + static_cast<std::ptrdiff_t>(last)};
}

}  // namespace

void KeyframeTiming::KeyframeStarted() {
  start_ = last_ = Clock::now();
  active_ = true;
  pending_.fill(-1);
}

void KeyframeTiming::StageEnded(core::MapperStage stage) {
  const auto now = Clock::now();
  pending_[static_cast<std::size_t>(stage)] =
      std::chrono::duration<double, std::milli>(now - last_).count();
  last_ = now;
  if (stage != core::MapperStage::kRooms || !active_) return;
  // A keyframe's stages are kept only once it is mapped (a refused keyframe ends early), so
  // every stage's n-th entry is the n-th keyframe's.
  for (std::size_t s = 0; s < stages_.size(); ++s)
    stages_[s].push_back(std::max(0.0, pending_[s]));  // a stage not run took 0
  total_.push_back(std::chrono::duration<double, std::milli>(now - start_).count());
  active_ = false;
  // The resident set at the end of each run, to see whether memory is flat.
  last_rss_mb_ = ResidentMb();
  if (total_.size() % kGrowthKeyframes == 0) rss_mb_.push_back(last_rss_mb_);
}

double KeyframeTiming::TotalP99(std::size_t first, std::size_t last) const {
  last = std::min(last, total_.size());
  if (first >= last) return 0;
  return Percentile(Slice(total_, first, last), 0.99);
}

double KeyframeTiming::ResidentMb() {
  std::FILE* f = std::fopen("/proc/self/statm", "r");
  if (f == nullptr) return 0;
  unsigned long long size_pages = 0, resident_pages = 0;
  const int read = std::fscanf(f, "%llu %llu", &size_pages, &resident_pages);
  std::fclose(f);
  if (read != 2) return 0;
  return static_cast<double>(resident_pages) * static_cast<double>(sysconf(_SC_PAGESIZE)) / 1e6;
}

double KeyframeTiming::Percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(
      std::min<double>(static_cast<double>(v.size() - 1), p * static_cast<double>(v.size())))];
}

void KeyframeTiming::Print(std::FILE* out) const {
  std::fprintf(out, "per keyframe [ms]        p50     p90     p99     max\n");
  for (std::size_t s = 0; s < stages_.size(); ++s) {
    const auto& v = stages_[s];
    std::fprintf(out, "  %-18s %7.2f %7.2f %7.2f %7.2f\n",
                 core::ToString(static_cast<core::MapperStage>(s)), Percentile(v, 0.5),
                 Percentile(v, 0.9), Percentile(v, 0.99), Percentile(v, 1.0));
  }
  std::fprintf(out, "  %-18s %7.2f %7.2f %7.2f %7.2f\n", "total", Percentile(total_, 0.5),
               Percentile(total_, 0.9), Percentile(total_, 0.99), Percentile(total_, 1.0));
  // How the cost grows with the map: the total of each run of kGrowthKeyframes keyframes.
  std::fprintf(out, "per keyframe total by map size [ms]   p50     p99     max  RSS at end [MB]\n");
  for (std::size_t first = 0, run = 0; first < total_.size(); first += kGrowthKeyframes, ++run) {
    const std::size_t last = std::min(total_.size(), first + kGrowthKeyframes);
    const std::vector<double> v = Slice(total_, first, last);
    std::fprintf(out, "  keyframes %5zu-%-5zu         %7.2f %7.2f %7.2f  %7.1f\n", first, last - 1,
                 Percentile(v, 0.5), Percentile(v, 0.99), Percentile(v, 1.0),
                 run < rss_mb_.size() ? rss_mb_[run] : last_rss_mb_);
  }
  // Which stages grow: each stage's p50 and p99 per run (one value per keyframe and stage).
  std::fprintf(out, "per stage by map size [ms], p50/p99 per run of %zu keyframes\n",
               kGrowthKeyframes);
  for (std::size_t s = 0; s < stages_.size(); ++s) {
    const auto& v = stages_[s];
    std::fprintf(out, "  %-18s", core::ToString(static_cast<core::MapperStage>(s)));
    for (std::size_t first = 0; first < v.size(); first += kGrowthKeyframes) {
      const std::vector<double> r = Slice(v, first, std::min(v.size(), first + kGrowthKeyframes));
      std::fprintf(out, " %.1f/%.1f", Percentile(r, 0.5), Percentile(r, 0.99));
    }
    std::fprintf(out, "\n");
  }
  std::fprintf(out, "per sweep between keyframes [ms] (scan tracking), %zu sweeps\n",
               sweeps_.size());
  std::fprintf(out, "  %-18s %7.2f %7.2f %7.2f %7.2f\n", "sweep", Percentile(sweeps_, 0.5),
               Percentile(sweeps_, 0.9), Percentile(sweeps_, 0.99), Percentile(sweeps_, 1.0));
}

}  // namespace msgraphs::tools
