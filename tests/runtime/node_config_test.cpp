// SPDX-License-Identifier: MIT
#include "msgraphs/runtime/config/node_config.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "msgraphs/runtime/config/key_value_file.hpp"

namespace msgraphs::runtime::config {
namespace {

bool Parse(const std::string& text,
           NodeConfig& out,
           std::string& error,
           const std::vector<std::string>& overrides = {}) {
  return ParseNodeConfig(text, "robot.conf", "/base", overrides, out, error);
}

std::string ErrorOf(const std::string& text, const std::vector<std::string>& overrides = {}) {
  NodeConfig c;
  std::string error;
  EXPECT_FALSE(Parse(text, c, error, overrides)) << text;
  return error;
}

TEST(KeyValueFile, SectionsKeysCommentsAndLines) {
  KeyValueFile f;
  std::string error;
  ASSERT_TRUE(ParseKeyValueText("# top\n[a]\nx = 1  # note\n\n[b.c]\ny=two words\npath = /p#1\n",
                                "f", f, error))
      << error;
  ASSERT_EQ(f.entries.size(), 3u);
  EXPECT_EQ(f.entries[0].value, "1");
  EXPECT_EQ(f.entries[0].line, 3);
  EXPECT_EQ(f.entries[1].section, "b.c");
  EXPECT_EQ(f.entries[1].value, "two words");
  EXPECT_EQ(f.entries[2].value, "/p#1");  // '#' inside a value is not a comment
}

TEST(KeyValueFile, SyntaxErrorsNameTheLine) {
  KeyValueFile f;
  std::string error;
  EXPECT_FALSE(ParseKeyValueText("[a]\nno equals sign\n", "f", f, error));
  EXPECT_EQ(error, "f:2: expected 'key = value'");
  EXPECT_FALSE(ParseKeyValueText("x = 1\n", "f", f, error));
  EXPECT_NE(error.find("f:1: 'x' is outside any [section]"), std::string::npos);
  EXPECT_FALSE(ParseKeyValueText("[a]\nx = 1\nx = 2\n", "f", f, error));
  EXPECT_NE(error.find("f:3: 'x' repeats line 2"), std::string::npos);
  EXPECT_FALSE(ParseKeyValueText("[a\n", "f", f, error));
  EXPECT_FALSE(ParseKeyValueText(std::string("[a]\nx = \0\n", 10), "f", f, error));
}

TEST(NodeConfig, MinimalFileGetsDefaults) {
  NodeConfig c;
  std::string error;
  ASSERT_TRUE(Parse("[robot]\nid = 3\n", c, error)) << error;
  EXPECT_EQ(c.robot.value, 3);
  EXPECT_EQ(c.name, "robot3");
  EXPECT_EQ(c.collab.robot, 3);
  EXPECT_EQ(c.lidar_source, LidarSource::kUdp);
  EXPECT_EQ(c.link.dds.discovery, link::Discovery::kMulticast);
  EXPECT_TRUE(c.collab.mode.walls && c.collab.mode.fine);
}

TEST(NodeConfig, ReadsEveryKind) {
  NodeConfig c;
  std::string error;
  ASSERT_TRUE(
      Parse("[robot]\nid = 2\n[lidar]\nT_base_lidar = 0.1 0 0.3 0 0 90\n"
            "[collab]\nmode = rooms\ncloud = q8\n[link]\ndiscovery = unicast\n"
            "initial_peers = 10.0.0.2 10.0.0.3\nmax_kbytes_per_s = 250\n"
            "[output]\ndir = out/r2\n"
            "[mapping]\nscan_match_max_fitness_m2 = 0.04\nscan_match_fitness_window = 50\n"
            "scan_match_fitness_outlier_z = 3\n"
            "[rooms]\ndoor_cut_clearance_m = 0.6\nclose_openings_up_to_m = 1.6\n",
            c, error))
      << error;
  EXPECT_DOUBLE_EQ(c.mapper.scan_match_max_fitness_m2, 0.04);
  EXPECT_EQ(c.mapper.scan_match_fitness_window, 50u);
  EXPECT_DOUBLE_EQ(c.mapper.scan_match_fitness_outlier_z, 3.0);
  EXPECT_FLOAT_EQ(c.mapper.rooms.segmentation.door_cut_clearance_m, 0.6f);
  EXPECT_FLOAT_EQ(c.mapper.rooms.segmentation.close_openings_up_to_m, 1.6f);
  EXPECT_NEAR(c.mapper.T_base_lidar.translation().x(), 0.1, 1e-12);
  const Eigen::Vector3d x_in_base = c.mapper.T_base_lidar.linear() * Eigen::Vector3d::UnitX();
  EXPECT_NEAR(x_in_base.y(), 1.0, 1e-9);  // yaw 90 degrees
  EXPECT_FALSE(c.collab.mode.walls || c.collab.mode.fine);
  EXPECT_EQ(c.collab.cloud_encoding, core::CloudEncoding::kQuantised8);
  EXPECT_FLOAT_EQ(c.collab.cloud_step_m, 0.05f);
  EXPECT_EQ(c.link.dds.initial_peers.size(), 2u);
  EXPECT_EQ(c.link.max_bytes_per_s, 250000u);
  EXPECT_EQ(c.output_dir, "/base/out/r2");  // relative to the file's folder
}

TEST(NodeConfig, ErrorsNameFileLineAndKey) {
  EXPECT_EQ(ErrorOf("[lidar]\nsource = udp\n"), "robot.conf: [robot] id is required (1..65535)");
  EXPECT_EQ(ErrorOf("[robot]\nid = 0\n"), "robot.conf:2: robot.id: must be in [1, 65535], not 0");
  EXPECT_EQ(ErrorOf("[robot]\nid = 1.5\n"), "robot.conf:2: robot.id: must be a whole number");
  EXPECT_EQ(
      ErrorOf("[robot]\nid = 1\n[mapping]\nbase_heigth_m = 0.5\n"),
      "robot.conf:4: mapping.base_heigth_m: unknown key (misspelt, or in the wrong section?)");
  EXPECT_EQ(ErrorOf("[robot]\nid = 1\n[lidar]\nsource = usb\n"),
            "robot.conf:4: lidar.source: 'usb' is not one of: udp, pcap");
  EXPECT_EQ(ErrorOf("[robot]\nid = 1\n[link]\ninterfaces = eth0\n"),
            "robot.conf: [link] interface is not a dotted IPv4 address");
  EXPECT_EQ(ErrorOf("[robot]\nid = 1\n[lidar]\nT_base_lidar = 0 0 nan 0 0 0\n"),
            "robot.conf:4: lidar.T_base_lidar: needs six numbers: x y z [m] roll pitch yaw [deg]");
  EXPECT_EQ(ErrorOf("[robot]\nid = 1\n[replay]\npace = lockstep\n"),
            "robot.conf: [replay] pace = lockstep needs recorded inputs (lidar pcap and odometry "
            "candump)");
  EXPECT_EQ(ErrorOf("[robot]\nid = 1\n[lidar]\nsource = pcap\npcap = missing.pcap\n"),
            "robot.conf: [lidar] pcap: no such file: /base/missing.pcap");
  EXPECT_EQ(ErrorOf("[robot]\nid = 1\n[link]\ndiscovery = server\n"),
            "robot.conf: [link] discovery server must be IPv4:port");
  EXPECT_EQ(ErrorOf("[robot]\nid = 1\n[link]\nmax_kbytes_per_s = 5\n"),
            "robot.conf: [link] radio budget below 10 kB/s cannot carry a room cloud");
  EXPECT_EQ(ErrorOf("[robot]\nid = 1\n[led]\nline = 17\n"), "robot.conf: [led] line needs chip");
  EXPECT_EQ(ErrorOf("[robot]\nid = 1\n[mapping]\nscan_match_fitness_window = 5\n"),
            "robot.conf:4: mapping.scan_match_fitness_window: must be in [10, 100000], not 5");
  EXPECT_EQ(ErrorOf("[robot]\nid = 1\n[rooms]\nclose_openings_up_to_m = -1\n"),
            "robot.conf:4: rooms.close_openings_up_to_m: must be in [0, 10], not -1");
}

TEST(NodeConfig, OverridesReplaceOrAddAndAreCheckedToo) {
  NodeConfig c;
  std::string error;
  ASSERT_TRUE(Parse("[robot]\nid = 1\n", c, error, {"robot.id=4", "link.domain=17"})) << error;
  EXPECT_EQ(c.robot.value, 4);
  EXPECT_EQ(c.link.dds.domain_id, 17u);
  EXPECT_EQ(ErrorOf("[robot]\nid = 1\n", {"link.domain=300"}),
            "--set: link.domain: must be in [0, 232], not 300");
  EXPECT_EQ(ErrorOf("[robot]\nid = 1\n", {"nodot=1"}), "--set nodot=1: expected section.key=value");
}

// A snapshot made under other mapper settings is not loaded (checkpoint.hpp): the CRC changes with
// every key that shapes the map, and with none that does not (the robot's speed of replay, the
// link, the checkpoint's own keys).
TEST(NodeConfig, TheMapperSettingsCrcFollowsWhatShapesTheMapOnly) {
  const auto crc_with = [](const std::vector<std::string>& overrides) {
    NodeConfig c;
    std::string error;
    EXPECT_TRUE(Parse("[robot]\nid = 3\n", c, error, overrides)) << error;
    return c.mapper_settings_crc;
  };
  const std::uint32_t base = crc_with({});
  EXPECT_EQ(crc_with({}), base);
  EXPECT_EQ(crc_with({"robot.id=4"}), base);
  EXPECT_EQ(crc_with({"link.domain=9"}), base);
  EXPECT_EQ(crc_with({"checkpoint.snapshot_every_keyframes=7"}), base);
  EXPECT_EQ(crc_with({"checkpoint.sync_period_s=1"}), base);
  for (const char* shapes :
       {"mapping.keyframe_spacing_m=0.7", "mapping.max_range_m=30", "mapping.max_keyframes=2000",
        "mapping.cloud_store_points=2000000", "mapping.full_solve_lag_keyframes=2",
        "mapping.grid_half_extent_m=60", "mapping.track_scans=false",
        "mapping.sparsify_plane_share=0.2", "rooms.door_cut_clearance_m=0.6", "odometry.sigma_per_m=0.05",
        "lidar.T_base_lidar=0 0 0.4 0 0 0"})
    EXPECT_NE(crc_with({shapes}), base) << shapes;
}

TEST(NodeConfig, TheShippedExampleIsValid) {
  NodeConfig c;
  std::string error;
  ASSERT_TRUE(LoadNodeConfig(MSGRAPHS_EXAMPLE_CONFIG, {}, c, error)) << error;
  EXPECT_EQ(c.robot.value, 1);
}

TEST(NodeConfig, UnreadableOrHugeFilesAreRefused) {
  NodeConfig c;
  std::string error;
  EXPECT_FALSE(LoadNodeConfig("/nonexistent/robot.conf", {}, c, error));
  EXPECT_NE(error.find("cannot read"), std::string::npos);
  const auto big = std::filesystem::temp_directory_path() / "msgraphs_big.conf";
  {
    std::ofstream out(big);
    out << std::string(2 << 20, '#');
  }
  EXPECT_FALSE(LoadNodeConfig(big.string(), {}, c, error));
  EXPECT_NE(error.find("larger than 1 MiB"), std::string::npos);
  std::filesystem::remove(big);
}

}  // namespace
}  // namespace msgraphs::runtime::config
