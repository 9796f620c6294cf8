// SPDX-License-Identifier: MIT
#include "options.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <utility>

namespace msgraphs::tools::collab {
namespace {

bool Number(const char* text, double& value) {
  char* end = nullptr;
  value = std::strtod(text, &end);
  return end != text && *end == '\0' && std::isfinite(value);
}

}  // namespace

bool ParseOptions(int argc, char** argv, Options& o, std::string& error) {
  bool step_given = false;
  auto fail = [&error](std::string why) {
    error = std::move(why);
    return false;
  };
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const char* v = i + 1 < argc ? argv[i + 1] : nullptr;
    const bool flag = a == "--markdown" || a == "--timing";
    if (v == nullptr && !flag) return fail(a + ": unknown option or missing value");
    if (a == "--markdown") {
      o.markdown = true;
      continue;
    }
    if (a == "--timing") {
      o.timing = true;
      continue;
    }
    ++i;  // every other option takes a value
    double number = 0;
    if (a == "--run") {
      o.run = v;
    } else if (a == "--out") {
      o.out_dir = v;
    } else if (a == "--summary") {
      o.summary_path = v;
    } else if (a == "--explain") {
      o.explain_dir = v;
    } else if (a == "--exchange-every-s") {
      if (!Number(v, o.every_s) || !(o.every_s > 0)) return fail(a + " takes seconds > 0");
    } else if (a == "--until-s") {
      // The mission as it stood at S: the report and --explain judge the maps and decisions of
      // that moment (a merge at 20 s undone at 30 s is seen as it was decided).
      if (!Number(v, o.until_s) || !(o.until_s > 0)) return fail(a + " takes seconds > 0");
    } else if (a == "--max-keyframes") {
      // A whole number of keyframes; the graph's own validation judges the value (OpenRobot).
      // At most 65,536: every store sized from it is allocated at Init, for every robot.
      if (!Number(v, number) || !(number >= 1) || number > 65536 || number != std::floor(number))
        return fail(a + " takes a whole number of keyframes from 1 to 65536");
      o.max_keyframes = static_cast<std::size_t>(number);
    } else if (a == "--delay-s") {
      // ROBOT=SECONDS: that robot starts later in mission time (a late joiner when longer than
      // the others' missions: it arrives with its whole map).
      int robot = 0;
      double delay = 0;
      if (std::sscanf(v, "%d=%lf", &robot, &delay) != 2 || robot < 1 || !(delay >= 0) ||
          !std::isfinite(delay))
        return fail("--delay-s takes ROBOT=SECONDS");
      o.delays_s[robot] = delay;
    } else if (a == "--mode") {
      o.mode_name = v;
      if (o.mode_name == "rooms")
        o.session.mode = {false, false};
      else if (o.mode_name == "rooms-fine")
        o.session.mode = {false, true};
      else if (o.mode_name == "rooms-walls")
        o.session.mode = {true, false};
      else if (o.mode_name == "rooms-walls-fine")
        o.session.mode = {true, true};
      else if (o.mode_name == "keyframes")
        o.keyframes = true;
      else
        return fail("unknown mode " + o.mode_name);
    } else if (a == "--cloud") {
      o.cloud_name = v;
      if (o.cloud_name == "f32")
        o.session.cloud_encoding = core::CloudEncoding::kFloat32;
      else if (o.cloud_name == "q16")
        o.session.cloud_encoding = core::CloudEncoding::kQuantised16;
      else if (o.cloud_name == "q8")
        o.session.cloud_encoding = core::CloudEncoding::kQuantised8;
      else
        return fail("--cloud is f32, q16 or q8");
    } else if (a == "--cloud-step") {
      if (!Number(v, number) || !(number > 0)) return fail(a + " takes metres > 0");
      o.session.cloud_step_m = static_cast<float>(number);
      step_given = true;
    } else if (a == "--places") {
      // The merge decision's fallback (place_evidence.hpp): on with the session's byte budget
      // per peer, off to measure what it adds.
      const std::string f = v;
      if (f != "on" && f != "off") return fail("--places is on or off");
      if (f == "off") o.session.places.budget_bytes_per_peer = 0;
    } else if (a == "--feedback") {
      const std::string f = v;
      if (f != "on" && f != "off") return fail("--feedback is on or off");
      o.feedback = f == "on";
    } else if (a == "--wrong-origin-m") {
      if (!Number(v, o.evaluation.wrong_origin_m) || !(o.evaluation.wrong_origin_m > 0))
        return fail(a + " takes metres > 0");
    } else if (a == "--wrong-origin-deg") {
      if (!Number(v, o.evaluation.wrong_origin_deg) || !(o.evaluation.wrong_origin_deg > 0))
        return fail(a + " takes degrees > 0");
    } else {
      return fail("unknown option " + a);
    }
  }
  // int8 clouds at the int16 default step would not fit a room: 5 cm unless a step was given.
  if (o.session.cloud_encoding == core::CloudEncoding::kQuantised8 && !step_given)
    o.session.cloud_step_m = 0.05f;
  if (o.run.empty()) return fail("--run DIR is required");
  return true;
}

StartDelay ResolveStartDelay(int robot,
                             const std::map<int, double>& mission_delays_s,
                             const std::map<int, double>& option_delays_s) {
  if (auto d = option_delays_s.find(robot); d != option_delays_s.end())
    return {d->second, "--delay-s"};
  if (auto d = mission_delays_s.find(robot); d != mission_delays_s.end())
    return {d->second, "mission.txt"};
  return {};
}

bool ReadStartDelays(const std::string& path, std::map<int, double>& delays_s, std::string& error) {
  std::ifstream in(path);
  if (!in) return true;  // no mission.txt: no delays
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    std::istringstream s(line);
    std::string word;
    int robot = 0;
    if (!(s >> word) || word != "robot" || !(s >> robot)) continue;
    for (std::string key; s >> key;) {
      if (key != "start_delay_s") continue;
      std::string value;
      double delay = 0;
      if (!(s >> value) || !Number(value.c_str(), delay) || delay < 0) {
        error = path + ":" + std::to_string(number) + ": start_delay_s of robot " +
                std::to_string(robot) + " is not a number of seconds >= 0";
        return false;
      }
      delays_s[robot] = delay;
      break;
    }
  }
  return true;
}

}  // namespace msgraphs::tools::collab
