// SPDX-License-Identifier: MIT
// Starting the host tools as real processes from tests, and loopback receivers for them.
#pragma once

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "msgraphs/platform/udp_socket.hpp"

extern char** environ;

namespace msgraphs::test {

inline pid_t Spawn(const std::vector<std::string>& args) {
  std::vector<char*> argv;
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  pid_t pid = -1;
  EXPECT_EQ(posix_spawn(&pid, argv[0], nullptr, nullptr, argv.data(), environ), 0) << args[0];
  return pid;
}

inline int Wait(pid_t pid) {
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128;
}

inline bool Exited(pid_t pid, int& code) {
  int status = 0;
  if (waitpid(pid, &status, WNOHANG) != pid) return false;
  code = WIFEXITED(status) ? WEXITSTATUS(status) : 128;
  return true;
}

inline platform::UdpReceiver Receiver(std::size_t payload, int buffer_bytes = 8 << 20) {
  platform::UdpReceiverConfig c;
  c.bind = {kIpv4Loopback, 0};
  c.expected_payload_bytes = payload;
  c.receive_buffer_bytes = buffer_bytes;
  return platform::UdpReceiver::Open(c).value();
}

inline std::string Temp(const char* name) {
  return (std::filesystem::temp_directory_path() / ("msgraphs_" + std::to_string(getpid()) + "_" + name)).string();
}

}  // namespace msgraphs::test
