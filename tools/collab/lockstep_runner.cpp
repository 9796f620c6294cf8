// SPDX-License-Identifier: MIT
#include "lockstep_runner.hpp"

#include <chrono>
#include <cmath>

namespace msgraphs::tools::collab {
namespace {

ExchangeRecord Record(const Mission& mission, double t) {
  ExchangeRecord r;
  r.mission_time_s = t;
  for (int k = 0; k < kMessageTypes; ++k)
    r.bytes[static_cast<std::size_t>(k)] = mission.accounting.Total(k);
  return r;
}

}  // namespace

MissionRun RunLockStep(Mission& mission,
                       double every_s,
                       double until_s,
                       const std::function<void(double)>& after_exchange) {
  const auto t0 = std::chrono::steady_clock::now();
  MissionRun run;
  double next_exchange = every_s;
  for (;;) {
    Robot* next = nullptr;
    for (auto& r : mission.robots) {
      if (!r->scans_done && (next == nullptr || NextScanTime_s(*r) < NextScanTime_s(*next)))
        next = r.get();
    }
    if (next == nullptr) break;
    const double t = NextScanTime_s(*next);
    if (until_s > 0 && t >= until_s) break;
    if (t >= next_exchange) {
      mission.Exchange(t);
      run.exchanges.push_back(Record(mission, t));
      after_exchange(t);
      // The next period after t (a delayed robot can leave a gap of several periods).
      next_exchange = (std::floor(t / every_s) + 1) * every_s;
    }
    run.mission_time_s = t;
    ProcessNextScan(*next);
  }
  for (auto& r : mission.robots) {
    r->solver.Join();  // its last background solve, done
    static_cast<void>(r->mapper.Finish());
  }
  mission.Exchange(run.mission_time_s);
  run.exchanges.push_back(Record(mission, run.mission_time_s));
  after_exchange(run.mission_time_s);
  // The last exchange's wall priors into the final maps.
  if (mission.feedback && !mission.keyframes) {
    for (auto& r : mission.robots) static_cast<void>(r->mapper.Finish());
  }
  run.run_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return run;
}

}  // namespace msgraphs::tools::collab
