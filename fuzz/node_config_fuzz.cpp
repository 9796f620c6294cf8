// SPDX-License-Identifier: MIT
// libFuzzer target: arbitrary text as a node configuration file. Invariants: no crash; a
// refusal always carries a message naming the file; an accepted configuration passes every
// validation the node relies on (robot id set, link and mapper settings valid).
#include <cstdint>
#include <cstdlib>
#include <string>

#include "msgraphs/runtime/config/node_config.hpp"

using namespace msgraphs::runtime::config;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  NodeConfig config;
  std::string error;
  if (!ParseNodeConfig(text, "fuzz.conf", "/nonexistent", {}, config, error)) {
    if (error.rfind("fuzz.conf", 0) != 0) std::abort();  // every message names the file
    return 0;
  }
  if (!config.robot.valid() || config.collab.robot != config.robot.value) std::abort();
  if (!config.link.Validate() || !config.mapper.Validate() || !config.collab.Validate())
    std::abort();
  return 0;
}
