// SPDX-License-Identifier: MIT
// pcl_read_pcd FILE: loads a PCD file with PCL's own reader (as PCL-based tools and
// CloudCompare's PCL plugin do) and prints "points N"; exit 1 when PCL refuses it.
// Test support only (demo_fleet_test.sh): the onboard code never sees PCL.
#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>

#include <cmath>
#include <cstdio>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: pcl_read_pcd FILE\n");
    return 2;
  }
  pcl::PointCloud<pcl::PointXYZ> cloud;
  if (pcl::io::loadPCDFile<pcl::PointXYZ>(argv[1], cloud) != 0) {
    std::fprintf(stderr, "pcl_read_pcd: PCL could not read %s\n", argv[1]);
    return 1;
  }
  std::size_t finite = 0;
  for (const auto& p : cloud.points) {
    if (std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)) ++finite;
  }
  std::printf("points %zu finite %zu\n", cloud.size(), finite);
  return 0;
}
