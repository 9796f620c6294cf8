// SPDX-License-Identifier: MIT
#include "msgraphs/runtime/outputs/pcd_file.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>

namespace msgraphs::runtime {

std::uint64_t VoxelKey(const Eigen::Vector3f& p, float voxel_m) {
  auto cell = [voxel_m](float v) {
    return static_cast<std::uint64_t>(static_cast<std::int64_t>(std::floor(v / voxel_m)) +
                                      (1 << 20)) &
           0x1FFFFF;
  };
  return cell(p.x()) | cell(p.y()) << 21 | cell(p.z()) << 42;
}

Status WritePcd(const std::string& path, std::span<const Eigen::Vector3f> points) {
  const std::string temp = path + ".tmp";
  std::FILE* file = std::fopen(temp.c_str(), "wb");
  if (file == nullptr) return Error{Errc::kIo, "pcd: cannot create the file", errno};
  // VIEWPOINT is the identity: the points are already in the map frame.
  std::fprintf(file,
               "# .PCD v0.7 - Point Cloud Data file format\n"
               "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
               "WIDTH %zu\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS %zu\nDATA binary\n",
               points.size(), points.size());
  // Eigen::Vector3f is three packed floats; PCD binary is little-endian like every target.
  static_assert(sizeof(Eigen::Vector3f) == 3 * sizeof(float));
  const std::size_t written =
      points.empty() ? 0 : std::fwrite(points.data(), sizeof(Eigen::Vector3f), points.size(), file);
  const bool ok = written == points.size() && std::fflush(file) == 0;
  const int saved = errno;
  std::fclose(file);
  if (!ok) {
    std::remove(temp.c_str());
    return Error{Errc::kIo, "pcd: write failed", saved};
  }
  if (std::rename(temp.c_str(), path.c_str()) != 0)
    return Error{Errc::kIo, "pcd: cannot rename into place", errno};
  return Ok();
}

Expected<std::vector<Eigen::Vector3f>> ReadPcd(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) return Error{Errc::kIo, "pcd: cannot open the file", errno};
  const std::string bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  if (file.bad()) return Error{Errc::kIo, "pcd: read failed", errno};
  return ParsePcd(bytes);
}

Expected<std::vector<Eigen::Vector3f>> ParsePcd(std::string_view bytes) {
  std::istringstream in{std::string(bytes)};
  std::vector<std::string> fields;
  std::vector<int> sizes, counts;
  std::vector<char> types;
  long long width = -1, height = 1, points = -1;
  std::string data;
  std::string line;
  while (data.empty() && std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream words(line);
    std::string key;
    words >> key;
    if (key == "FIELDS") {
      for (std::string f; words >> f;) fields.push_back(f);
    } else if (key == "SIZE") {
      for (int v; words >> v;) sizes.push_back(v);
    } else if (key == "TYPE") {
      for (char v; words >> v;) types.push_back(v);
    } else if (key == "COUNT") {
      for (int v; words >> v;) counts.push_back(v);
    } else if (key == "WIDTH") {
      words >> width;
    } else if (key == "HEIGHT") {
      words >> height;
    } else if (key == "POINTS") {
      words >> points;
    } else if (key == "DATA") {
      words >> data;
    }
  }
  if (data.empty()) return Error{Errc::kMalformed, "pcd: no DATA line"};
  if (counts.empty()) counts.assign(fields.size(), 1);
  if (fields.empty() || sizes.size() != fields.size() || types.size() != fields.size() ||
      counts.size() != fields.size())
    return Error{Errc::kMalformed, "pcd: FIELDS, SIZE, TYPE and COUNT disagree"};
  constexpr long long kMaxPoints = 1LL << 31;
  if (points < 0) {  // no POINTS line: WIDTH x HEIGHT, each checked before the product
    if (width < 0 || height < 0 || width > kMaxPoints || height > kMaxPoints)
      return Error{Errc::kMalformed, "pcd: bad WIDTH or HEIGHT"};
    points = width * height;
  }
  if (points < 0 || points > kMaxPoints) return Error{Errc::kMalformed, "pcd: bad point count"};
  // Byte offset (binary) and column (ascii) of x, y and z.
  long long offset[3] = {-1, -1, -1};
  std::size_t column[3] = {0, 0, 0};
  long long stride = 0, columns = 0;
  if (fields.size() > 1024) return Error{Errc::kMalformed, "pcd: too many fields"};
  for (std::size_t i = 0; i < fields.size(); ++i) {
    if (sizes[i] <= 0 || counts[i] <= 0 || sizes[i] > 8 || counts[i] > 4096)
      return Error{Errc::kMalformed, "pcd: bad field size or count"};
    const int axis = fields[i] == "x" ? 0 : fields[i] == "y" ? 1 : fields[i] == "z" ? 2 : -1;
    if (axis >= 0) {
      if (types[i] != 'F' || sizes[i] != 4 || counts[i] != 1)
        return Error{Errc::kUnsupported, "pcd: x y z must be float32"};
      offset[axis] = stride;
      column[axis] = static_cast<std::size_t>(columns);
    }
    stride += sizes[i] * counts[i];
    columns += counts[i];
  }
  if (columns > 65536) return Error{Errc::kMalformed, "pcd: too many values a point"};
  if (offset[0] < 0 || offset[1] < 0 || offset[2] < 0)
    return Error{Errc::kMalformed, "pcd: no x y z fields"};
  // What is left after the header bounds how many points can follow: a hostile POINTS line
  // must not make us reserve gigabytes.
  const std::streamoff header_end = in.tellg();
  const auto remaining =
      static_cast<long long>(bytes.size()) - (header_end < 0 ? 0 : static_cast<long long>(header_end));
  if (data == "binary" && points * stride > remaining)
    return Error{Errc::kMalformed, "pcd: file truncated"};
  std::vector<Eigen::Vector3f> out;
  out.reserve(static_cast<std::size_t>(std::min(points, remaining / 2 + 1)));
  auto keep = [&](float x, float y, float z) {
    if (std::isfinite(x) && std::isfinite(y) && std::isfinite(z)) out.emplace_back(x, y, z);
  };
  if (data == "binary") {
    std::vector<char> record(static_cast<std::size_t>(stride));
    for (long long p = 0; p < points; ++p) {
      if (!in.read(record.data(), stride)) return Error{Errc::kMalformed, "pcd: file truncated"};
      float v[3];
      for (int a = 0; a < 3; ++a) std::memcpy(&v[a], record.data() + offset[a], sizeof(float));
      keep(v[0], v[1], v[2]);
    }
  } else if (data == "ascii") {
    std::vector<double> values(static_cast<std::size_t>(columns));
    for (long long p = 0; p < points; ++p) {
      for (double& v : values) {
        std::string word;
        if (!(in >> word)) return Error{Errc::kMalformed, "pcd: file truncated"};
        v = std::strtod(word.c_str(), nullptr);  // "nan" reads as NaN, skipped below
      }
      keep(static_cast<float>(values[column[0]]), static_cast<float>(values[column[1]]),
           static_cast<float>(values[column[2]]));
    }
  } else {
    return Error{Errc::kUnsupported, "pcd: only binary and ascii data are read"};
  }
  return out;
}

}  // namespace msgraphs::runtime
