// SPDX-License-Identifier: MIT
#include "msgraphs/runtime/config/node_config.hpp"

#include <arpa/inet.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>

#include "msgraphs/base/crc32.hpp"
#include "msgraphs/runtime/config/key_value_file.hpp"

namespace msgraphs::runtime::config {

namespace {

namespace fs = std::filesystem;

// Typed access to the entries; the first problem is kept with its line.
class Reader {
 public:
  Reader(const KeyValueFile& file, std::string base_dir)
      : file_(file), base_dir_(std::move(base_dir)) {}

  bool ok() const { return error_.empty(); }
  const std::string& error() const { return error_; }

  void Fail(const KeyValueEntry* e, const std::string& why) {
    if (!error_.empty()) return;
    // Line 0: the entry came from a --set override, not from the file.
    const std::string where = e == nullptr   ? file_.name
                              : e->line == 0 ? "--set"
                                             : file_.name + ":" + std::to_string(e->line);
    error_ =
        e != nullptr ? where + ": " + e->section + "." + e->key + ": " + why : where + ": " + why;
  }

  bool Has(const char* section, const char* key) { return file_.Find(section, key) != nullptr; }

  void Number(const char* section, const char* key, double lo, double hi, double& out) {
    const KeyValueEntry* e = file_.Find(section, key);
    if (e == nullptr) return;
    char* end = nullptr;
    const double v = std::strtod(e->value.c_str(), &end);
    if (e->value.empty() || *end != '\0' || !std::isfinite(v))
      return Fail(e, "'" + e->value + "' is not a number");
    if (v < lo || v > hi) {
      std::ostringstream range;
      range << "must be in [" << lo << ", " << hi << "], not " << e->value;
      return Fail(e, range.str());
    }
    out = v;
  }
  template <typename Int>
  void Integer(const char* section, const char* key, double lo, double hi, Int& out) {
    double v = static_cast<double>(out);
    const KeyValueEntry* e = file_.Find(section, key);
    if (e == nullptr) return;
    e->used = false;  // Number marks it again
    Number(section, key, lo, hi, v);
    if (ok() && v != std::floor(v)) return Fail(e, "must be a whole number");
    out = static_cast<Int>(v);
  }
  void Float(const char* section, const char* key, double lo, double hi, float& out) {
    double v = out;
    Number(section, key, lo, hi, v);
    out = static_cast<float>(v);
  }
  void Bool(const char* section, const char* key, bool& out) {
    const KeyValueEntry* e = file_.Find(section, key);
    if (e == nullptr) return;
    if (e->value == "true" || e->value == "on" || e->value == "yes") {
      out = true;
    } else if (e->value == "false" || e->value == "off" || e->value == "no") {
      out = false;
    } else {
      Fail(e, "must be true or false, not '" + e->value + "'");
    }
  }
  void String(const char* section, const char* key, std::string& out) {
    if (const KeyValueEntry* e = file_.Find(section, key)) out = e->value;
  }
  void Path(const char* section, const char* key, std::string& out) {
    const KeyValueEntry* e = file_.Find(section, key);
    if (e == nullptr || e->value.empty()) return;
    fs::path p(e->value);
    out = p.is_absolute() ? p.string() : (fs::path(base_dir_) / p).lexically_normal().string();
  }
  void Ipv4(const char* section, const char* key, std::string& out) {
    const KeyValueEntry* e = file_.Find(section, key);
    if (e == nullptr) return;
    in_addr addr{};
    if (inet_pton(AF_INET, e->value.c_str(), &addr) != 1)
      return Fail(e, "'" + e->value + "' is not a dotted IPv4 address");
    out = e->value;
  }
  void List(const char* section, const char* key, std::vector<std::string>& out) {
    const KeyValueEntry* e = file_.Find(section, key);
    if (e == nullptr) return;
    out.clear();
    std::istringstream in(e->value);
    for (std::string item; in >> item;) out.push_back(item);
  }
  /// One of `names`; returns its index through `out`.
  template <typename Enum, std::size_t N>
  void Choice(const char* section, const char* key, const char* const (&names)[N], Enum& out) {
    const KeyValueEntry* e = file_.Find(section, key);
    if (e == nullptr) return;
    std::string all;
    for (std::size_t i = 0; i < N; ++i) {
      if (e->value == names[i]) {
        out = static_cast<Enum>(i);
        return;
      }
      all += (i == 0 ? "" : ", ") + std::string(names[i]);
    }
    Fail(e, "'" + e->value + "' is not one of: " + all);
  }
  /// "x y z roll pitch yaw" in metres and degrees.
  void Pose(const char* section, const char* key, Eigen::Isometry3d& out) {
    const KeyValueEntry* e = file_.Find(section, key);
    if (e == nullptr) return;
    std::istringstream in(e->value);
    double v[6];
    for (double& x : v) {
      if (!(in >> x) || !std::isfinite(x))
        return Fail(e, "needs six numbers: x y z [m] roll pitch yaw [deg]");
    }
    std::string rest;
    if (in >> rest) return Fail(e, "needs six numbers: x y z [m] roll pitch yaw [deg]");
    if (std::abs(v[0]) > 5 || std::abs(v[1]) > 5 || std::abs(v[2]) > 5)
      return Fail(e, "translation beyond 5 m: not a sensor on a robot");
    const double k = std::numbers::pi / 180.0;
    out = Eigen::Translation3d(v[0], v[1], v[2]) *
          Eigen::AngleAxisd(v[5] * k, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(v[4] * k, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(v[3] * k, Eigen::Vector3d::UnitX());
  }

  /// Every entry not read is a misspelt or unknown key.
  void CheckAllUsed() {
    for (const KeyValueEntry& e : file_.entries) {
      if (!e.used) return Fail(&e, "unknown key (misspelt, or in the wrong section?)");
    }
  }

 private:
  const KeyValueFile& file_;
  std::string base_dir_;
  std::string error_;
};

constexpr const char* kLidarSources[] = {"udp", "pcap"};
constexpr const char* kOdometrySources[] = {"socketcan", "candump", "udp"};
constexpr const char* kPaces[] = {"lockstep", "recorded"};
constexpr const char* kModes[] = {"rooms", "rooms-fine", "rooms-walls", "rooms-walls-fine"};
constexpr const char* kClouds[] = {"f32", "q16", "q8"};
constexpr const char* kDiscovery[] = {"multicast", "unicast", "server"};

bool ApplyOverrides(const std::vector<std::string>& overrides,
                    KeyValueFile& file,
                    std::string& error) {
  for (const std::string& o : overrides) {
    const std::size_t dot = o.find('.'), eq = o.find('=');
    if (dot == std::string::npos || eq == std::string::npos || dot > eq) {
      error = "--set " + o + ": expected section.key=value";
      return false;
    }
    KeyValueEntry entry{o.substr(0, dot), o.substr(dot + 1, eq - dot - 1), o.substr(eq + 1), 0};
    bool replaced = false;
    for (KeyValueEntry& e : file.entries) {
      if (e.section == entry.section && e.key == entry.key) {
        e.value = entry.value;
        replaced = true;
      }
    }
    if (!replaced) file.entries.push_back(entry);
  }
  return true;
}

}  // namespace

bool ParseNodeConfig(const std::string& text,
                     const std::string& name,
                     const std::string& base_dir,
                     const std::vector<std::string>& overrides,
                     NodeConfig& out,
                     std::string& error) {
  KeyValueFile file;
  if (!ParseKeyValueText(text, name, file, error)) return false;
  if (!ApplyOverrides(overrides, file, error)) return false;
  NodeConfig c;
  c.file = name;
  Reader r(file, base_dir);

  if (!r.Has("robot", "id")) r.Fail(nullptr, "[robot] id is required (1..65535)");
  r.Integer("robot", "id", 1, 65535, c.robot.value);
  c.name = "robot" + std::to_string(c.robot.value);
  r.String("robot", "name", c.name);

  r.Choice("lidar", "source", kLidarSources, c.lidar_source);
  r.Path("lidar", "pcap", c.pcap_path);
  r.Ipv4("lidar", "bind", c.bind_address);
  r.Integer("lidar", "data_port", 0, 65535, c.data_port);
  r.Integer("lidar", "position_port", 0, 65535, c.position_port);
  r.Ipv4("lidar", "sensor", c.sensor_address);
  r.Pose("lidar", "T_base_lidar", c.mapper.T_base_lidar);

  r.Choice("odometry", "source", kOdometrySources, c.odometry_source);
  r.Path("odometry", "candump", c.candump_path);
  r.String("odometry", "interface", c.can_interface);
  r.Integer("odometry", "udp_port", 0, 65535, c.can_udp_port);
  // The odometry factor's noise (LocalMapperConfig): the robot's odometry, not the simulator's.
  r.Number("odometry", "sigma_per_m", 0.0, 1.0, c.mapper.odometry_sigma_per_m);
  r.Number("odometry", "sigma_min_m", 1e-4, 1.0, c.mapper.odometry_sigma_min_m);
  r.Number("odometry", "rotation_sigma_per_m", 0.0, 1.0, c.mapper.odometry_rotation_sigma_per_m);
  r.Number("odometry", "rotation_sigma_min_rad", 1e-5, 1.0, c.mapper.odometry_rotation_sigma_min);
  r.Number("odometry", "slip_gate_chi2", 0.0, 1e6, c.mapper.odometry_gate_chi2);
  r.Number("odometry", "motion_seed_max_age_s", 0.0, 60.0, c.mapper.motion_seed_max_age_s);

  r.Choice("replay", "pace", kPaces, c.pace);
  r.Number("replay", "speed", 0.01, 1000, c.speed);

  r.Number("mapping", "base_height_m", 0.05, 3.0, c.mapper.base_height_m);
  r.Number("mapping", "keyframe_spacing_m", 0.1, 10.0, c.mapper.keyframe_spacing_m);
  double keyframe_angle_deg = c.mapper.keyframe_angle_rad * 180.0 / std::numbers::pi;
  r.Number("mapping", "keyframe_angle_deg", 1.0, 180.0, keyframe_angle_deg);
  c.mapper.keyframe_angle_rad = keyframe_angle_deg * std::numbers::pi / 180.0;
  r.Float("mapping", "min_range_m", 0.0, 10.0, c.mapper.min_range_m);
  r.Float("mapping", "max_range_m", 1.0, 120.0, c.mapper.max_range_m);
  r.Integer("mapping", "max_keyframes", 16, 1000000, c.mapper.graph.max_keyframes);
  // The share of a removed keyframe's hop that its carried plane observations get (0: dropped;
  // s_graph.hpp, sparsify_plane_share). Below 1: the joined chain always keeps a share.
  r.Number("mapping", "sparsify_plane_share", 0.0, 0.99, c.mapper.graph.sparsify_plane_share);
  r.Integer("mapping", "cloud_store_points", 100000, 100000000, c.mapper.cloud_store_points);
  // The full solve on its own thread, applied this many keyframes after it began (0: on the
  // SLAM thread; local_mapper.hpp, full_solve_lag_keyframes).
  r.Integer("mapping", "full_solve_lag_keyframes", 0, 1000, c.mapper.full_solve_lag_keyframes);
  // The free-space grid: a square window, first centred on the start, that follows the robot
  // (grid_follows_robot), at its resolution (memory grows with the square of the extent:
  // 1024 x 1024 cells at the default).
  double grid_half_extent_m =
      0.5 * static_cast<double>(c.mapper.grid.width) * static_cast<double>(c.mapper.grid.resolution_m);
  r.Number("mapping", "grid_half_extent_m", 10.0, 1000.0, grid_half_extent_m);
  const int cells = static_cast<int>(std::ceil(2.0 * grid_half_extent_m / static_cast<double>(c.mapper.grid.resolution_m)));
  c.mapper.grid.width = c.mapper.grid.height = cells;
  c.mapper.grid.origin_m = Eigen::Vector2f::Constant(-0.5f * static_cast<float>(cells) * c.mapper.grid.resolution_m);
  r.Bool("mapping", "grid_follows_robot", c.mapper.grid_follows_robot);
  // Scan matching's fitness limit: a floor, widened to the robot's own outlier bound (FitnessGate).
  r.Number("mapping", "scan_match_max_fitness_m2", 1e-4, 10.0, c.mapper.scan_match_max_fitness_m2);
  r.Integer("mapping", "scan_match_fitness_window", 10, 100000, c.mapper.scan_match_fitness_window);
  r.Number("mapping", "scan_match_fitness_outlier_z", 0.0, 100.0, c.mapper.scan_match_fitness_outlier_z);
  // Scan tracking: every sweep registered against the local map (local_mapper.hpp, track_scans).
  r.Bool("mapping", "track_scans", c.mapper.track_scans);
  r.Float("mapping", "tracking_voxel_m", 0.1, 2.0, c.mapper.tracking_voxel_m);
  r.Number("mapping", "tracking_prior_sigma_m", 1e-3, 10.0, c.mapper.tracking_prior_sigma_m);
  r.Number("mapping", "tracking_prior_sigma_rad", 1e-4, 3.0, c.mapper.tracking_prior_sigma_rad);
  // Room segmentation (RoomSegmentationConfig): the building's doorways and corridors, not the
  // simulator's. An opening narrower than close_openings_up_to_m is closed before segmenting; it
  // must stay below the building's narrowest corridor (docs/perception.md, "Openings").
  r.Float("rooms", "door_cut_clearance_m", 0.1, 5.0, c.mapper.rooms.segmentation.door_cut_clearance_m);
  r.Float("rooms", "close_openings_up_to_m", 0.0, 10.0, c.mapper.rooms.segmentation.close_openings_up_to_m);

  int mode = 3;
  r.Choice("collab", "mode", kModes, mode);
  c.collab.mode = {mode >= 2, mode % 2 == 1};
  r.Choice("collab", "cloud", kClouds, c.collab.cloud_encoding);
  if (c.collab.cloud_encoding == core::CloudEncoding::kQuantised8) c.collab.cloud_step_m = 0.05f;
  r.Float("collab", "cloud_step_m", 0.001, 0.1, c.collab.cloud_step_m);
  r.Integer("collab", "max_peers", 1, 64, c.collab.max_peers);
  r.Number("collab", "exchange_period_s", 0.5, 600, c.exchange_period_s);
  r.Number("collab", "match_period_s", 0.05, 60, c.match_period_s);
  r.Number("collab", "request_retry_s", 0.5, 600, c.request_retry_s);
  r.Bool("collab", "feedback", c.feedback);
  r.Bool("collab", "marginals_in_background", c.marginals_in_background);
  // The merge decision's fallback (place_evidence.hpp): bytes of place clouds per peer, each way.
  double place_budget_kb = static_cast<double>(c.collab.places.budget_bytes_per_peer) / 1000.0;
  r.Number("collab", "place_budget_kb", 0, 10000, place_budget_kb);
  c.collab.places.budget_bytes_per_peer = static_cast<std::size_t>(place_budget_kb * 1000.0);

  link::DdsSettings& dds = c.link.dds;
  r.Integer("link", "domain", 0, 232, dds.domain_id);
  r.Bool("link", "loopback_only", dds.loopback_only);
  r.List("link", "interfaces", dds.interfaces);
  r.Choice("link", "discovery", kDiscovery, dds.discovery);
  r.List("link", "initial_peers", dds.initial_peers);
  r.String("link", "discovery_server", dds.discovery_server);
  r.Integer("link", "discovery_server_id", 0, 255, dds.discovery_server_id);
  r.Number("link", "lease_duration_s", 1, 3600, dds.lease_duration_s);
  double max_kbytes_per_s = c.link.max_bytes_per_s / 1000.0;
  r.Number("link", "max_kbytes_per_s", 0, 1e6, max_kbytes_per_s);
  c.link.max_bytes_per_s = static_cast<std::uint32_t>(max_kbytes_per_s * 1000.0);
  r.Integer("link", "graph_history", 1, 4096, c.link.graph_history);
  r.Integer("link", "reader_depth", 16, 65536, c.link.reader_depth);
  r.Number("link", "telemetry_hz", 0.1, 50, c.telemetry_hz);

  r.Integer("runtime", "realtime_priority", 0, 99, c.realtime_priority);
  r.Bool("runtime", "lock_memory", c.lock_memory);
  r.Number("runtime", "status_period_s", 0.1, 3600, c.status_period_s);
  r.Integer("runtime", "scan_queue", 1, 64, c.scan_queue);
  r.Integer("runtime", "odometry_queue", 16, 65536, c.odometry_queue);
  r.Number("runtime", "exit_after_done_s", 0, 3600, c.exit_after_done_s);
  r.Number("runtime", "max_run_s", 0, 1e7, c.max_run_s);

  r.String("led", "chip", c.led_chip);
  r.String("led", "line", c.led_line);
  r.Bool("led", "active_low", c.led_active_low);

  r.Bool("ros", "enabled", c.ros_enabled);
  r.Number("ros", "cloud_period_s", 0.5, 3600, c.ros_cloud_period_s);

  r.Path("checkpoint", "dir", c.checkpoint_dir);
  r.Number("checkpoint", "sync_period_s", 0.1, 3600, c.checkpoint_sync_s);
  r.Number("checkpoint", "max_speed_mps", 0.1, 20, c.relocalise_max_speed_mps);
  r.Integer("checkpoint", "snapshot_every_keyframes", 0, 1000000, c.snapshot_every_keyframes);

  r.Path("output", "dir", c.output_dir);
  r.CheckAllUsed();
  if (!r.ok()) {
    error = r.error();
    return false;
  }

  // Cross-field rules.
  auto fail = [&](const std::string& why) {
    error = name + ": " + why;
    return false;
  };
  if (c.lidar_source == LidarSource::kPcap && c.pcap_path.empty())
    return fail("[lidar] source = pcap needs pcap = FILE");
  if (c.odometry_source == OdometrySource::kCandump && c.candump_path.empty())
    return fail("[odometry] source = candump needs candump = FILE");
  if (c.pace == Pace::kLockstep &&
      (c.lidar_source != LidarSource::kPcap || c.odometry_source != OdometrySource::kCandump))
    return fail("[replay] pace = lockstep needs recorded inputs (lidar pcap and odometry candump)");
  if (c.lidar_source == LidarSource::kPcap && !fs::exists(c.pcap_path))
    return fail("[lidar] pcap: no such file: " + c.pcap_path);
  if (c.odometry_source == OdometrySource::kCandump && !fs::exists(c.candump_path))
    return fail("[odometry] candump: no such file: " + c.candump_path);
  if (c.mapper.min_range_m >= c.mapper.max_range_m)
    return fail("[mapping] min_range_m must be below max_range_m");
  if (!c.led_line.empty() && c.led_chip.empty()) return fail("[led] line needs chip");
  if (!c.led_chip.empty() && c.led_line.empty()) return fail("[led] chip needs line");
  c.collab.robot = c.robot.value;
  // The session counts Match calls, not seconds (core has no clock).
  c.collab.request_retry_calls =
      static_cast<std::uint32_t>(std::max(1.0, std::ceil(c.request_retry_s / c.match_period_s)));
  if (Status s = c.link.Validate(); !s) return fail(std::string("[link] ") + s.error().detail);
  if (Status s = c.mapper.Validate(); !s) return fail(std::string("[mapping] ") + s.error().detail);
  if (Status s = c.collab.Validate(); !s) return fail(std::string("[collab] ") + s.error().detail);
  c.mapper_settings_crc = MapperSettingsCrc(c.mapper);
  out = std::move(c);
  return true;
}

std::uint32_t MapperSettingsCrc(const core::LocalMapperConfig& m) {
  // Every value the file's [mapping], [rooms], [odometry] noise and [lidar] T_base_lidar keys
  // set, as the mapper holds them. The graph's own config is checked by its snapshot already.
  std::vector<double> v;
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 4; ++k) v.push_back(m.T_base_lidar.matrix()(r, k));
  v.insert(v.end(), {m.odometry_sigma_per_m, m.odometry_sigma_min_m, m.odometry_rotation_sigma_per_m,
                     m.odometry_rotation_sigma_min, m.odometry_gate_chi2, m.motion_seed_max_age_s,
                     m.base_height_m, m.keyframe_spacing_m, m.keyframe_angle_rad,
                     static_cast<double>(m.min_range_m), static_cast<double>(m.max_range_m),
                     static_cast<double>(m.graph.max_keyframes), m.graph.sparsify_plane_share,
                     static_cast<double>(m.cloud_store_points),
                     static_cast<double>(m.full_solve_lag_keyframes),
                     static_cast<double>(m.grid.width), static_cast<double>(m.grid.height),
                     static_cast<double>(m.grid.origin_m.x()), static_cast<double>(m.grid.origin_m.y()),
                     m.grid_follows_robot ? 1.0 : 0.0, m.scan_match_max_fitness_m2,
                     static_cast<double>(m.scan_match_fitness_window),
                     m.scan_match_fitness_outlier_z, m.track_scans ? 1.0 : 0.0,
                     static_cast<double>(m.tracking_voxel_m), m.tracking_prior_sigma_m,
                     m.tracking_prior_sigma_rad,
                     static_cast<double>(m.rooms.segmentation.door_cut_clearance_m),
                     static_cast<double>(m.rooms.segmentation.close_openings_up_to_m)});
  std::vector<std::uint8_t> bytes(v.size() * 8);
  std::memcpy(bytes.data(), v.data(), bytes.size());
  return Crc32(bytes);
}

bool LoadNodeConfig(const std::string& path,
                    const std::vector<std::string>& overrides,
                    NodeConfig& out,
                    std::string& error) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    error = path + ": cannot read the configuration file";
    return false;
  }
  std::ostringstream text;
  text << in.rdbuf();
  if (text.str().size() > (1 << 20)) {
    error = path + ": larger than 1 MiB: not a configuration file";
    return false;
  }
  const std::string base = fs::path(path).parent_path().string();
  return ParseNodeConfig(text.str(), path, base.empty() ? "." : base, overrides, out, error);
}

}  // namespace msgraphs::runtime::config
