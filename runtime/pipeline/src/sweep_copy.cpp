// SPDX-License-Identifier: MIT
#include "msgraphs/runtime/pipeline/sweep_copy.hpp"

#include <algorithm>

namespace msgraphs::runtime {

std::size_t SweepCapacity(const drivers::velodyne::ScanAssemblerConfig& assembler,
                          std::size_t mapper_max_scan_points) {
  return std::max(assembler.capacity_points, mapper_max_scan_points);
}

std::size_t CopySweep(const drivers::velodyne::Scan& scan, std::vector<Eigen::Vector3f>& points_lidar,
                      std::vector<float>& time_offset_s) {
  points_lidar.clear();
  time_offset_s.clear();
  const std::size_t fits = std::min({scan.points.size(), points_lidar.capacity(), time_offset_s.capacity()});
  for (std::size_t i = 0; i < fits; ++i) {
    const auto& p = scan.points[i];
    points_lidar.emplace_back(p.x_m, p.y_m, p.z_m);
    time_offset_s.push_back(static_cast<float>(static_cast<double>(p.time_offset_ns) * 1e-9));
  }
  return scan.points.size() - fits + scan.dropped_points;
}

}  // namespace msgraphs::runtime
