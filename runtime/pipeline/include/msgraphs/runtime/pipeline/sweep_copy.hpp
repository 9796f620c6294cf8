// SPDX-License-Identifier: MIT
// The LiDAR thread's copy of an assembled sweep into a scan slot of the queue to the SLAM
// thread. The slots are reserved once, before the threads start, for the most points a sweep
// can carry (SweepCapacity), so this copy never grows them: it stops at the slot's reserved
// capacity and returns how many points it left out, with those the assembler itself dropped,
// for the node's counters. Allocates nothing (tests/runtime/sweep_copy_test.cpp).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "msgraphs/drivers/velodyne/scan_assembler.hpp"

namespace msgraphs::runtime {

/// Points a slot reserves: the assembler's capacity (every point a sweep can hold), and at
/// least what the mapper takes.
std::size_t SweepCapacity(const drivers::velodyne::ScanAssemblerConfig& assembler,
                          std::size_t mapper_max_scan_points);

/// Copies `scan` (lidar frame; time offsets in seconds) into the two vectors, at most their
/// capacity() points. Returns the points left out: beyond that capacity, plus the sweep's own
/// `dropped_points` (its assembler was full).
std::size_t CopySweep(const drivers::velodyne::Scan& scan, std::vector<Eigen::Vector3f>& points_lidar,
                      std::vector<float>& time_offset_s);

}  // namespace msgraphs::runtime
