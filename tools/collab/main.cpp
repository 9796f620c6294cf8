// SPDX-License-Identifier: MIT
// msgraphs_collab: a multi-robot mission (simulator recordings) through the whole Multi S-Graphs
// pipeline in one process, deterministically: every robot's local S-Graph in lock-step by
// mission time; every `--exchange-every-s` each robot's core::CollabSession (the same class the
// onboard node runs) publishes what changed, and the messages cross an in-process radio (the
// real wire encodings, decoded by every peer, bytes counted per type and link). Receivers match
// rooms by Scan Context, request room clouds for fine alignment (modes with "fine"), keep the
// largest mutually consistent set of matches per robot pair, and solve their collaborative graph.
//
// At the end it reports every robot's own map against its truth, and every view (robot A's
// estimate of robot B, every ordered pair): merged, mission time of the first merge, whether a
// merge was later withdrawn, the origin error against the truth and a verdict (wrong beyond
// --wrong-origin-m or --wrong-origin-deg); per viewer the ATE of the aggregated trajectory
// (every robot it merged, through its estimated origins, one SE(3) alignment to the truth, every
// keyframe paired with its own robot's truth interpolated at its stamp); room matches accepted
// and rejected (and how many accepted ones are wrong against the truth); data exchanged per
// message type and link. --mode keyframes runs the keyframe-level baseline instead of rooms,
// through the same tables.
//
//   msgraphs_collab --run DIR [--mode rooms|rooms-fine|rooms-walls|rooms-walls-fine|keyframes]
//                   [--cloud f32|q16|q8] [--cloud-step 0.01] [--feedback on|off]
//                   [--exchange-every-s 10] [--delay-s ROBOT=SECONDS]...
//                   [--wrong-origin-m 0.5] [--wrong-origin-deg 2] [--out DIR] [--summary FILE]
//                   [--until-s S] [--markdown]
//
// --feedback on (the default) gives each robot's local S-Graph the other robots' measurements of
// its matched walls, through the merged origins (CollabSession::PlanePriors).
// Start delays come from DIR/mission.txt (`robot N ... start_delay_s S`) when it has them;
// --delay-s N=S overrides robot N's.
// --out DIR writes robotB_in_robotA.tum for every view and bytes.csv (outputs.hpp); --summary
// FILE the machine-readable summary (JSON, docs/collab-summary.md). --until-s S ends the mission
// at mission time S: everything is reported as it stood then.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <string>

#include "evaluation.hpp"
#include "explain.hpp"
#include "lockstep_runner.hpp"
#include "merge_tracker.hpp"
#include "mission.hpp"
#include "options.hpp"
#include "outputs.hpp"
#include "report.hpp"
#include "robot.hpp"

int main(int argc, char** argv) {
  using namespace msgraphs::tools::collab;
  namespace fs = std::filesystem;
  Options o;
  std::string error;
  if (!ParseOptions(argc, argv, o, error)) {
    std::fprintf(stderr, "collab: %s\n%s", error.c_str(), kUsage);
    return 2;
  }
  std::map<int, double> mission_delays_s;
  if (!ReadStartDelays((fs::path(o.run) / "mission.txt").string(), mission_delays_s, error)) {
    std::fprintf(stderr, "collab: %s\n", error.c_str());
    return 2;
  }
  Mission mission;
  mission.keyframes = o.keyframes;
  mission.feedback = o.feedback;
  mission.cloud_encoding = o.session.cloud_encoding;
  if (auto s = mission.matcher.Init({}); !s) {
    std::fprintf(stderr, "collab: %s\n", s.error().detail);
    return 1;
  }
  for (int i = 0; i < 10; ++i) {
    const fs::path dir = fs::path(o.run) / ("robot" + std::to_string(i + 1));
    if (!fs::exists(dir / "velodyne.pcap")) break;
    const StartDelay delay = ResolveStartDelay(i + 1, mission_delays_s, o.delays_s);
    auto robot = OpenRobot(dir.string(), i, delay.delay_s, o.max_keyframes, o.timing, o.session,
                           error);
    if (!robot) {
      std::fprintf(stderr, "collab: %s\n", error.c_str());
      return 1;
    }
    robot->delay_source = delay.source;
    mission.robots.push_back(std::move(robot));
  }
  if (mission.robots.size() < 2) {
    std::fprintf(stderr, "collab: %s holds fewer than two robots\n", o.run.c_str());
    return 2;
  }

  MergeTracker tracker(mission.robots.size());
  const MissionRun run = RunLockStep(mission, o.every_s, o.until_s, [&](double mission_time_s) {
    tracker.AfterExchange(mission, mission_time_s);
  });
  const Evaluation evaluation = Evaluate(mission, tracker, o.evaluation);
  const std::vector<ViewExplanation> explanations = ExplainViews(mission, evaluation, o.explain_dir);
  const ReportInput report{o, mission, run, evaluation, explanations};

  if (!o.out_dir.empty() && !WriteOutputs(o.out_dir, mission, evaluation, run, error)) {
    std::fprintf(stderr, "collab: %s\n", error.c_str());
    return 1;
  }
  if (!o.summary_path.empty()) {
    const fs::path path(o.summary_path);
    std::error_code ec;
    if (path.has_parent_path()) fs::create_directories(path.parent_path(), ec);
    std::ofstream out(path);
    out << JsonSummary(report);
    if (!out.flush()) {
      std::fprintf(stderr, "collab: cannot write %s\n", o.summary_path.c_str());
      return 1;
    }
  }
  const std::string text = o.markdown ? MarkdownRow(report) : TextReport(report);
  std::fputs(text.c_str(), stdout);
  if (o.timing) {
    for (const auto& r : mission.robots) {
      const msgraphs::core::SGraphStats g = r->mapper.graph().stats();
      std::printf("robot %d timing: %zu keyframes mapped, %zu in the graph (peak %zu, %zu sparsified)\n",
                  r->id(), r->timing.total().size(), g.keyframes, g.keyframes_peak, g.sparsified);
      r->timing.Print(stdout);
    }
    std::printf("resident set at the end: %.1f MB (the whole fleet, one process)\n",
                msgraphs::tools::KeyframeTiming::ResidentMb());
  }
  return 0;
}
