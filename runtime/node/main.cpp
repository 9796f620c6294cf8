// SPDX-License-Identifier: MIT
// msgraphs_node: one process per robot (docs/runtime.md).
//
//   msgraphs_node --config FILE [--set section.key=value]... [--check-config]
//   msgraphs_node --self-check [--domain N]
//   msgraphs_node --heartbeat --robot-id N [--domain N] [--loopback] [--peer IPv4]...
//                 [--unicast | --discovery-server IPv4:PORT]
//                 [--expect-peers K] [--duration-s S] [--rate-hz R]
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "modes.hpp"
#include "msgraphs/platform/fail_handler.hpp"

namespace {

void Usage() {
  std::fputs(
      "usage: msgraphs_node --config FILE [--set section.key=value]... [--check-config]\n"
      "       msgraphs_node --self-check [--domain N]\n"
      "       msgraphs_node --heartbeat --robot-id N [--domain N] [--loopback] [--peer IPv4]...\n"
      "                     [--unicast | --discovery-server IPv4:PORT]\n"
      "                     [--expect-peers K] [--duration-s S] [--rate-hz R]\n",
      stderr);
}

// Parses a whole-string number; rejects trailing garbage, which strtol alone would accept.
bool ParseNumber(const char* text, double* out) {
  char* end = nullptr;
  *out = std::strtod(text, &end);
  return end != text && *end == '\0';
}

}  // namespace

int main(int argc, char** argv) {
  msgraphs::platform::InstallStderrFailHandler();
  using msgraphs::runtime::HeartbeatModeOptions;
  enum class Mode { kNone, kNode, kSelfCheck, kHeartbeat } mode = Mode::kNone;
  HeartbeatModeOptions options;
  std::string config_path;
  std::vector<std::string> overrides;
  bool check_only = false;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const bool has_value = i + 1 < argc;
    double number = 0.0;
    auto take_number = [&](double lo, double hi) {
      if (!has_value || !ParseNumber(argv[++i], &number) || number < lo || number > hi) {
        std::fprintf(stderr, "msgraphs_node: %s needs a number in [%g, %g]\n", arg.c_str(), lo, hi);
        std::exit(2);
      }
      return number;
    };
    if (arg == "--config" && has_value) {
      mode = Mode::kNode;
      config_path = argv[++i];
    } else if (arg == "--set" && has_value) {
      overrides.emplace_back(argv[++i]);
    } else if (arg == "--check-config") {
      check_only = true;
    } else if (arg == "--self-check") {
      mode = Mode::kSelfCheck;
    } else if (arg == "--heartbeat") {
      mode = Mode::kHeartbeat;
    } else if (arg == "--robot-id") {
      options.robot_id.value = static_cast<std::uint16_t>(take_number(1, 65535));
    } else if (arg == "--domain") {
      options.dds.domain_id = static_cast<std::uint32_t>(take_number(0, 232));
    } else if (arg == "--loopback") {
      options.dds.loopback_only = true;
    } else if (arg == "--peer" && has_value) {
      options.dds.initial_peers.emplace_back(argv[++i]);
    } else if (arg == "--unicast") {
      options.dds.discovery = msgraphs::runtime::link::Discovery::kUnicast;
    } else if (arg == "--discovery-server" && has_value) {
      options.dds.discovery = msgraphs::runtime::link::Discovery::kServer;
      options.dds.discovery_server = argv[++i];
    } else if (arg == "--expect-peers") {
      options.expect_peers = static_cast<int>(take_number(0, 1000));
    } else if (arg == "--duration-s") {
      options.duration_s = take_number(0.1, 86400);
    } else if (arg == "--rate-hz") {
      options.rate_hz = take_number(0.1, 1000);
    } else if (arg == "-h" || arg == "--help") {
      Usage();
      return 0;
    } else {
      std::fprintf(stderr, "msgraphs_node: unknown argument '%s'\n", arg.c_str());
      Usage();
      return 2;
    }
  }
  switch (mode) {
    case Mode::kNode:
      return msgraphs::runtime::RunNode(config_path, overrides, check_only);
    case Mode::kSelfCheck:
      return msgraphs::runtime::RunSelfCheck(options.dds.domain_id);
    case Mode::kHeartbeat:
      if (!options.robot_id.valid()) {
        std::fputs("msgraphs_node: --heartbeat needs --robot-id (1..65535)\n", stderr);
        return 2;
      }
      return msgraphs::runtime::RunHeartbeatMode(options);
    case Mode::kNone:
      break;
  }
  Usage();
  return 2;
}
