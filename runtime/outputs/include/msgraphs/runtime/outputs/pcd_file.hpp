// SPDX-License-Identifier: MIT
// Point cloud maps as PCD v0.7 files (binary, x y z float32): what PCL's loadPCDFile and
// CloudCompare open. The reader takes what this writer writes and the common variants other
// tools write (binary or ascii data, extra fields such as intensity, any field order); it
// refuses binary_compressed and anything malformed with a message.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "msgraphs/base/expected.hpp"

namespace msgraphs::runtime {

/// Writes `points` (metres, in whatever frame the caller names in the file name) as a binary
/// PCD. The file appears whole or not at all (written beside and renamed).
Status WritePcd(const std::string& path, std::span<const Eigen::Vector3f> points);

/// Reads the x y z fields of a PCD file; points with a non-finite coordinate are skipped.
Expected<std::vector<Eigen::Vector3f>> ReadPcd(const std::string& path);
/// The same from the file's bytes (what ReadPcd does after reading the file; fuzzed).
Expected<std::vector<Eigen::Vector3f>> ParsePcd(std::string_view bytes);

/// A voxel's key for thinning a map to one point per voxel: 21 bits per axis, unique within
/// +-52 km of the origin at 5 cm.
std::uint64_t VoxelKey(const Eigen::Vector3f& p, float voxel_m);

}  // namespace msgraphs::runtime
