// SPDX-License-Identifier: MIT
// libFuzzer target: arbitrary bytes as a PCD file (msgraphs_fleet_report reads the nodes' maps,
// and any other tool's PCD, through it). Invariants: no crash, no huge allocation from a hostile
// header (POINTS, COUNT, FIELDS), every point returned finite, a refusal carries a reason.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string_view>

#include "msgraphs/runtime/outputs/pcd_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  auto points = msgraphs::runtime::ParsePcd(bytes);
  if (!points) {
    if (points.error().detail == nullptr || std::strlen(points.error().detail) == 0) std::abort();
    return 0;
  }
  for (const Eigen::Vector3f& p : *points) {
    if (!p.allFinite()) std::abort();
  }
  // At most one point per byte of input: the data section must have held them.
  if (points->size() > size) std::abort();
  return 0;
}
