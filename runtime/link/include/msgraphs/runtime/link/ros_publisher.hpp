// SPDX-License-Identifier: MIT
// The collaborative map on ROS 2 topics, without ROS: RViz2 (Humble) on the same network shows
// it with no bridge. Topics, with <ns> = "msgraphs/<robot name>" and frame "<robot name>/map":
//
//   rt/<ns>/map_markers   visualization_msgs/MarkerArray  walls (boxes) and rooms (discs, labels)
//                                                         of this robot and every robot merged,
//                                                         in this robot's frame, colour per robot
//   rt/<ns>/map_cloud     sensor_msgs/PointCloud2         this robot's map (x y z float32, 0.2 m
//                                                         voxels); built only while someone listens
//   rt/<ns>/trajectory    nav_msgs/Path                   this robot's keyframes
//   rt/tf                 tf2_msgs/TFMessage              <ref>/map -> <robot>/map for every robot
//                                                         merged, from the alive robot with the
//                                                         lowest id only (one tree, no loops)
//
// Writers are reliable and transient-local with history 1: RViz2 gets the latest state when it
// starts, whichever reliability it asks for. They share the node's participant and radio cap
// (lowest priority).
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "msgraphs/base/expected.hpp"

namespace msgraphs::runtime::link {

class FleetLink;

/// Plain data for one publication, built by the node.
struct RosMapView {
  std::string frame;  ///< "<robot name>/map"
  double stamp_s = 0;
  struct Keyframe {
    double stamp_s = 0;
    Eigen::Isometry3d T_map_base = Eigen::Isometry3d::Identity();
  };
  std::vector<Keyframe> trajectory;
  struct Wall {
    std::uint16_t robot = 0;
    std::uint32_t id = 0;
    Eigen::Vector2d a = Eigen::Vector2d::Zero(), b = Eigen::Vector2d::Zero();  ///< ends, this frame
    double floor_z_m = 0;
  };
  std::vector<Wall> walls;
  struct Room {
    std::uint16_t robot = 0;
    std::uint32_t id = 0;
    Eigen::Vector2d centre = Eigen::Vector2d::Zero();
    double yaw_rad = 0, size_x_m = 0, size_y_m = 0, floor_z_m = 0;
  };
  std::vector<Room> rooms;
  std::vector<Eigen::Vector3f> cloud;  ///< map frame; empty: not published this time
  struct Origin {
    std::string frame;  ///< "<robot name>/map" of a merged robot
    Eigen::Isometry3d T_this_that = Eigen::Isometry3d::Identity();
  };
  std::vector<Origin> origins;  ///< published on rt/tf when `publish_tf`
  bool publish_tf = false;
};

class RosPublisher {
 public:
  /// Topics under "msgraphs/<name>", on `link`'s participant (which must outlive this).
  static Expected<std::unique_ptr<RosPublisher>> Create(FleetLink& link, const std::string& name);
  ~RosPublisher();
  RosPublisher(const RosPublisher&) = delete;
  RosPublisher& operator=(const RosPublisher&) = delete;

  /// True when a reader is matched with the map cloud (only then is it worth building).
  bool cloud_wanted() const;
  /// Publishes the markers, the trajectory, the cloud (when not empty) and the TF.
  void Publish(const RosMapView& view);
  std::uint64_t published() const;

 private:
  struct Impl;
  explicit RosPublisher(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace msgraphs::runtime::link
