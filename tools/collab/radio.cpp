// SPDX-License-Identifier: MIT
#include "radio.hpp"

namespace msgraphs::tools::collab {

const char* MessageTypeName(int type) {
  static constexpr const char* kNames[kMessageTypes] = {"distilled graph",      "room descriptors",
                                                        "room cloud requests",  "room clouds",
                                                        "free space",           "place requests",
                                                        "place clouds",         "keyframe descriptors", "keyframe clouds"};
  return type >= 0 && type < kMessageTypes ? kNames[type] : "unknown";
}

const char* MessageTypeKey(int type) {
  static constexpr const char* kKeys[kMessageTypes] = {"distilled_graph",      "room_descriptors",
                                                       "room_cloud_requests",  "room_clouds",
                                                       "free_space",           "place_requests",
                                                       "place_clouds",         "keyframe_descriptors", "keyframe_clouds"};
  return type >= 0 && type < kMessageTypes ? kKeys[type] : "unknown";
}

std::uint64_t Accounting::Total(int type) const {
  std::uint64_t sum = 0;
  for (const auto& [key, n] : bytes) {
    if (type < 0 || std::get<0>(key) == type) sum += n;
  }
  return sum;
}

std::uint64_t Accounting::Link(int from, int to) const {
  std::uint64_t sum = 0;
  for (const auto& [key, n] : bytes) {
    if (std::get<1>(key) == from && std::get<2>(key) == to) sum += n;
  }
  return sum;
}

}  // namespace msgraphs::tools::collab
