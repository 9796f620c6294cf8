// SPDX-License-Identifier: MIT
// Reading the public registration clouds in tests: binary little-endian PLY and binary PCD with
// float32 fields, x y z first. Tests only (the onboard code never reads files).
#pragma once

#include <cstdint>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace msgraphs::test {

inline std::vector<Eigen::Vector3f> ReadCloud(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string content((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::vector<Eigen::Vector3f> points;
  std::size_t count = 0, fields = 0, data = std::string::npos;
  std::istringstream header(content.substr(0, 4096));
  std::string line;
  const bool ply = content.rfind("ply", 0) == 0;
  while (std::getline(header, line)) {
    std::istringstream w(line);
    std::string key;
    w >> key;
    if (ply) {
      if (key == "element") {
        std::string what;
        w >> what >> count;
      } else if (key == "property") {
        ++fields;
      } else if (key == "end_header") {
        data = content.find("end_header\n") + 11;
        break;
      }
    } else {
      if (key == "FIELDS") {
        std::string f;
        while (w >> f) ++fields;
      } else if (key == "POINTS") {
        w >> count;
      } else if (key == "DATA") {
        data = content.find("DATA binary\n") + 12;
        break;
      }
    }
  }
  if (data == std::string::npos || fields < 3 || content.size() < data + count * fields * 4) return points;
  points.resize(count);
  for (std::size_t i = 0; i < count; ++i) {
    float xyz[3];
    std::memcpy(xyz, content.data() + data + i * fields * 4, sizeof(xyz));
    points[i] = {xyz[0], xyz[1], xyz[2]};
  }
  return points;
}

inline Eigen::Matrix4d ReadMatrix4(const std::string& path) {
  std::ifstream in(path);
  Eigen::Matrix4d m = Eigen::Matrix4d::Zero();
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) in >> m(r, c);
  return m;
}

}  // namespace msgraphs::test
