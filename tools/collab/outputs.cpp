// SPDX-License-Identifier: MIT
#include "outputs.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <system_error>

#include "msgraphs/runtime/outputs/merge_log_csv.hpp"
#include "msgraphs/tools/tum.hpp"
#include "radio.hpp"

namespace msgraphs::tools::collab {

bool WriteOutputs(const std::string& out_dir,
                  const Mission& mission,
                  const Evaluation& evaluation,
                  const MissionRun& run,
                  std::string& error) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  for (const ViewAte& view : evaluation.view_ate) {
    for (const auto& [robot, poses] : view.in_view) {
      const fs::path path = fs::path(out_dir) / ("robot" + std::to_string(robot) + "_in_robot" +
                                                 std::to_string(view.viewer) + ".tum");
      if (!WriteTum(path.string(), poses)) {
        error = "cannot write " + path.string();
        return false;
      }
    }
  }
  for (const auto& r : mission.robots) {
    if (mission.keyframes) break;
    const fs::path path = fs::path(out_dir) / ("merge_log_robot" + std::to_string(r->id()) + ".csv");
    std::ofstream log(path);
    log.precision(9);
    runtime::outputs::WriteMergeLogHeader(log, r->id(), "mission time");
    runtime::outputs::WriteMergeLogRows(log, r->merge_log);
    if (!log) {
      error = "cannot write " + path.string();
      return false;
    }
  }
  const fs::path csv = fs::path(out_dir) / "bytes.csv";
  std::FILE* f = std::fopen(csv.c_str(), "w");
  if (f == nullptr) {
    error = "cannot write " + csv.string();
    return false;
  }
  std::fprintf(f, "mission_time_s");
  for (int k = 0; k < kMessageTypes; ++k) std::fprintf(f, ",%s", MessageTypeName(k));
  std::fprintf(f, "\n");
  for (const ExchangeRecord& e : run.exchanges) {
    std::fprintf(f, "%.1f", e.mission_time_s);
    for (std::uint64_t b : e.bytes) std::fprintf(f, ",%llu", static_cast<unsigned long long>(b));
    std::fprintf(f, "\n");
  }
  if (std::fclose(f) != 0) {
    error = "cannot write " + csv.string();
    return false;
  }
  return true;
}

}  // namespace msgraphs::tools::collab
