// SPDX-License-Identifier: MIT
// msgraphs_collab's command line, and the robots' start delays from the recording's
// mission.txt (`robot N ... start_delay_s S ...`; an explicit --delay-s N=S overrides it; a
// missing file or key means no delay).
#pragma once

#include <cstddef>
#include <map>
#include <string>

#include "evaluation_config.hpp"
#include "msgraphs/core/collab/collab_session.hpp"

namespace msgraphs::tools::collab {

struct Options {
  std::string run, out_dir, summary_path;
  std::string explain_dir;  ///< --explain DIR: pictures of every view under the truth
  std::string mode_name = "rooms-walls-fine";
  std::string cloud_name = "q16";
  bool keyframes = false;  ///< --mode keyframes: the baseline
  bool feedback = true;
  bool markdown = false;
  double every_s = 10.0;
  double until_s = 0;  ///< --until-s: the mission ends at this mission time (0: at its end)
  /// --max-keyframes: each robot's S-Graph keyframe store (0: the mapper's default). Smaller
  /// than a mission's keyframes, the graph is sparsified to it (docs/s-graph.md).
  std::size_t max_keyframes = 0;
  /// --timing: each robot's per-stage keyframe timing and its growth with the map, and the
  /// process's resident set, after the report (issue 19's fleet evaluation).
  bool timing = false;
  std::map<int, double> delays_s;  ///< --delay-s: robot id -> start delay
  core::CollabSessionConfig session;
  EvaluationConfig evaluation;
};

inline constexpr const char* kUsage =
    "usage: msgraphs_collab --run DIR [--mode "
    "rooms|rooms-fine|rooms-walls|rooms-walls-fine|keyframes]\n"
    "                       [--cloud f32|q16|q8] [--cloud-step 0.01] [--feedback on|off]\n"
    "                       [--places on|off]\n"
    "                       [--exchange-every-s 10] [--delay-s ROBOT=SECONDS]...\n"
    "                       [--wrong-origin-m 0.5]\n"
    "                       [--wrong-origin-deg 2] [--out DIR] [--summary FILE] [--explain DIR]\n"
    "                       [--until-s S] [--max-keyframes N] [--timing] [--markdown]\n";

/// False with `error` on a bad command line (the caller prints it and the usage, exit 2).
bool ParseOptions(int argc, char** argv, Options& o, std::string& error);

struct StartDelay {
  double delay_s = 0;
  const char* source = "none";  ///< "none", "mission.txt" or "--delay-s"
};
/// Robot `robot`'s start delay: --delay-s when given, else mission.txt's, else none.
StartDelay ResolveStartDelay(int robot,
                             const std::map<int, double>& mission_delays_s,
                             const std::map<int, double>& option_delays_s);

/// Start delay per robot id from `path` (mission.txt). A missing file is no delay (true, empty);
/// a `start_delay_s` without a valid value (finite, >= 0) is an error (false, `error` set).
bool ReadStartDelays(const std::string& path, std::map<int, double>& delays_s, std::string& error);

}  // namespace msgraphs::tools::collab
