// SPDX-License-Identifier: MIT
// The SLAM thread's view of the collaborative map for the ROS 2 topics: this robot's keyframes
// and every merged robot's walls and rooms, brought into this robot's map frame. The own walls
// and rooms come from the publisher (SLAM thread); the other robots' from the session, which the
// collab thread owns: it refreshes a copy after each exchange and each Match that changed
// something, and the SLAM thread reads the copy.
#include <cmath>

#include "msgraphs/platform/clock.hpp"
#include "node_impl.hpp"

namespace msgraphs::runtime {

namespace {

std::string FrameOf(std::uint16_t robot) { return "robot" + std::to_string(robot) + "/map"; }

// A robot's distilled walls and rooms, through T (its map frame into ours).
void AddGraph(const core::DistilledGraph& g, const Eigen::Isometry3d& T, link::RosMapView& view) {
  const double floor_z = g.has_floor ? g.floor_z_m : 0.0;
  auto to_here = [&](const Eigen::Vector2d& p) {
    return T * Eigen::Vector3d(p.x(), p.y(), floor_z);
  };
  for (const core::DistilledWall& w : g.walls) {
    const Eigen::Vector3d a = to_here(w.a), b = to_here(w.b);
    view.walls.push_back({g.robot, w.id, a.head<2>(), b.head<2>(), 0.5 * (a.z() + b.z())});
  }
  const Eigen::Vector3d x_axis = T.linear() * Eigen::Vector3d::UnitX();
  const double yaw = std::atan2(x_axis.y(), x_axis.x());
  for (const core::DistilledRoom& r : g.rooms) {
    const Eigen::Vector3d c = to_here(r.centre);
    view.rooms.push_back(
        {g.robot, r.id, c.head<2>(), r.yaw_rad + yaw, r.size_x_m, r.size_y_m, c.z()});
  }
}

}  // namespace

void Node::Impl::RefreshRosFleet() {
  if (!ros) return;
  link::RosMapView& f = ros_fleet_scratch;
  f.walls.clear();
  f.rooms.clear();
  f.origins.clear();
  for (std::size_t i = 0; i < session.peers(); ++i) {
    const core::CollabPeerStats s = session.peer_stats(i);
    const core::DistilledGraph* g = session.peer_graph(s.robot);
    if (!s.merged || g == nullptr) continue;
    const Eigen::Isometry3d T = session.T_self_robot(s.robot);
    AddGraph(*g, T, f);
    f.origins.push_back({FrameOf(s.robot), T});
  }
  std::lock_guard<std::mutex> lock(ros_fleet_mutex);
  std::swap(ros_fleet.walls, f.walls);
  std::swap(ros_fleet.rooms, f.rooms);
  std::swap(ros_fleet.origins, f.origins);
}

void Node::Impl::PublishRos() {
  if (!ros) return;
  link::RosMapView& v = ros_view;
  v.frame = FrameOf(config.robot.value);
  v.walls.clear();
  v.rooms.clear();
  v.origins.clear();
  v.trajectory.clear();
  v.cloud.clear();
  const core::SGraph& graph = mapper.graph();
  double newest = 0;
  for (std::uint32_t k = graph.FirstKeyframe(); k != core::SGraph::kNoKeyframe;
       k = graph.NextKeyframe(k)) {
    v.trajectory.push_back({graph.keyframe_stamp(k), graph.keyframe_pose(k)});
    newest = graph.keyframe_stamp(k);  // oldest first: the last is the newest
  }
  v.stamp_s = newest;
  // The TF tree has one root: the alive robot with the lowest id publishes it.
  v.publish_tf = true;
  for (const link::FleetLink::PeerView& p : link->Peers())
    if (p.alive && p.telemetry.robot.value < config.robot.value) v.publish_tf = false;
  {
    // What the collab thread last took from the session: copied, never waited for across Match.
    AddGraph(publisher.graph(), Eigen::Isometry3d::Identity(), v);  // the own map, as just prepared
    std::lock_guard<std::mutex> lock(ros_fleet_mutex);
    v.walls.insert(v.walls.end(), ros_fleet.walls.begin(), ros_fleet.walls.end());
    v.rooms.insert(v.rooms.end(), ros_fleet.rooms.begin(), ros_fleet.rooms.end());
    v.origins = ros_fleet.origins;
  }
  const SteadyTime now = platform::SteadyNow();
  if (ros->cloud_wanted() &&
      (!ros_cloud_sent ||
       now - ros_cloud_last >= Duration::FromSeconds(config.ros_cloud_period_s))) {
    for (std::uint32_t k = 0; k < graph.keyframe_slots(); ++k) {
      const auto cloud = mapper.keyframe_cloud(k);
      if (cloud.empty()) continue;
      const Eigen::Isometry3f T = graph.keyframe_pose(k).cast<float>();
      for (const Eigen::Vector3f& p : cloud) v.cloud.push_back(T * p);
    }
    ros_cloud_last = now;
    ros_cloud_sent = true;
  }
  ros->Publish(v);
}

}  // namespace msgraphs::runtime
