// SPDX-License-Identifier: MIT
// The node proper: configuration, signals, the pipeline.
#include <csignal>
#include <cstdio>
#include <thread>

#include "modes.hpp"
#include "msgraphs/runtime/config/node_config.hpp"
#include "msgraphs/runtime/pipeline/node.hpp"

namespace msgraphs::runtime {

int RunNode(const std::string& config_path,
            const std::vector<std::string>& overrides,
            bool check_only) {
  config::NodeConfig config;
  std::string error;
  if (!config::LoadNodeConfig(config_path, overrides, config, error)) {
    std::fprintf(stderr, "msgraphs_node: configuration error: %s\n", error.c_str());
    return 2;
  }
  if (check_only) {
    std::printf("%s: valid (robot %u)\n", config_path.c_str(), config.robot.value);
    return 0;
  }
  // SIGINT and SIGTERM are blocked in every thread (Fast DDS's included, which inherit the
  // mask) and taken by one thread with sigwait: no async-signal-safety concerns, and the
  // shutdown is the normal one.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  std::atomic<bool> stop{false};
  std::atomic<bool> done{false};
  std::thread signal_thread([&] {
    const timespec slice{0, 100000000};
    while (!done.load()) {
      const int sig = sigtimedwait(&signals, nullptr, &slice);
      if (sig == SIGINT || sig == SIGTERM) {
        std::printf("msgraphs_node: %s received, shutting down\n",
                    sig == SIGINT ? "SIGINT" : "SIGTERM");
        std::fflush(stdout);
        stop = true;
      }
    }
  });
  int code = 0;
  {
    auto node = Node::Create(config, BuildLabel(), error);
    if (!node) {
      std::fprintf(stderr, "msgraphs_node: cannot start: %s\n", error.c_str());
      code = 1;
    } else {
      code = node->Run(stop);
    }
  }
  done = true;
  signal_thread.join();
  return code;
}

}  // namespace msgraphs::runtime
