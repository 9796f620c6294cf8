// SPDX-License-Identifier: MIT
#include "msgraphs/runtime/link/ros_publisher.hpp"

#include <array>
#include <cmath>
#include <cstring>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <unordered_set>

#include "RosHumblePubSubTypes.h"
#include "msgraphs/runtime/link/fleet_link.hpp"

namespace msgraphs::runtime::link {

namespace dds = eprosima::fastdds::dds;

namespace {

constexpr double kWallHeight_m = 2.4;  // drawn height of a wall above its floor
constexpr double kWallThickness_m = 0.08;
constexpr float kCloudVoxel_m = 0.2f;  // the stored clouds' resolution

// One colour per robot (cycled): distinct hues RViz users can tell apart.
std_msgs::msg::ColorRGBA RobotColour(std::uint16_t robot, float alpha) {
  static constexpr std::array<std::array<float, 3>, 6> kHues = {{{0.12f, 0.47f, 0.71f},
                                                                 {1.0f, 0.5f, 0.05f},
                                                                 {0.17f, 0.63f, 0.17f},
                                                                 {0.84f, 0.15f, 0.16f},
                                                                 {0.58f, 0.4f, 0.74f},
                                                                 {0.55f, 0.34f, 0.29f}}};
  const auto& h = kHues[(robot + kHues.size() - 1) % kHues.size()];
  std_msgs::msg::ColorRGBA c;
  c.r(h[0]);
  c.g(h[1]);
  c.b(h[2]);
  c.a(alpha);
  return c;
}

std_msgs::msg::Header MakeHeader(const std::string& frame, double stamp_s) {
  std_msgs::msg::Header h;
  const double sec = std::floor(stamp_s);
  h.stamp().sec(static_cast<std::int32_t>(sec));
  h.stamp().nanosec(static_cast<std::uint32_t>((stamp_s - sec) * 1e9));
  h.frame_id(frame);
  return h;
}

geometry_msgs::msg::Pose MakePose(const Eigen::Vector3d& t, const Eigen::Quaterniond& q) {
  geometry_msgs::msg::Pose p;
  p.position().x(t.x());
  p.position().y(t.y());
  p.position().z(t.z());
  p.orientation().x(q.x());
  p.orientation().y(q.y());
  p.orientation().z(q.z());
  p.orientation().w(q.w());
  return p;
}

}  // namespace

struct RosPublisher::Impl {
  dds::DomainParticipant* participant = nullptr;
  dds::Publisher* publisher = nullptr;
  dds::DataWriter *markers = nullptr, *cloud = nullptr, *path = nullptr, *tf = nullptr;
  std::vector<dds::Topic*> topics;
  std::uint64_t published = 0;
  std::size_t last_marker_count = 0;

  ~Impl() {
    if (participant == nullptr) return;
    for (dds::DataWriter* w : {markers, cloud, path, tf})
      if (w != nullptr) publisher->delete_datawriter(w);
    if (publisher != nullptr) participant->delete_publisher(publisher);
    for (dds::Topic* t : topics) participant->delete_topic(t);
  }

  dds::DataWriter* Writer(dds::TopicDataType* type, const std::string& topic_name) {
    dds::TypeSupport support(type);
    // Registering a type twice (several publishers) is refused harmlessly; the name counts.
    static_cast<void>(support.register_type(participant));
    dds::Topic* topic =
        participant->create_topic(topic_name, support.get_type_name(), dds::TOPIC_QOS_DEFAULT);
    if (topic == nullptr) return nullptr;
    topics.push_back(topic);
    dds::DataWriterQos q = dds::DATAWRITER_QOS_DEFAULT;
    q.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
    q.durability().kind = dds::TRANSIENT_LOCAL_DURABILITY_QOS;
    q.history().kind = dds::KEEP_LAST_HISTORY_QOS;
    q.history().depth = 1;
    q.endpoint().history_memory_policy = eprosima::fastrtps::rtps::DYNAMIC_REUSABLE_MEMORY_MODE;
    q.data_sharing().off();  // as rmw_fastrtps does
    q.publish_mode().kind = dds::ASYNCHRONOUS_PUBLISH_MODE;
    const auto& flows = participant->get_qos().flow_controllers();
    if (!flows.empty()) {
      q.publish_mode().flow_controller_name = flows.front()->name;
      q.properties().properties().emplace_back("fastdds.sfc.priority", "10");  // after the fleet
    }
    return publisher->create_datawriter(topic, q);
  }
};

RosPublisher::RosPublisher(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
RosPublisher::~RosPublisher() = default;

Expected<std::unique_ptr<RosPublisher>> RosPublisher::Create(FleetLink& link,
                                                             const std::string& name) {
  auto impl = std::make_unique<Impl>();
  impl->participant = static_cast<dds::DomainParticipant*>(link.participant());
  impl->publisher = impl->participant->create_publisher(dds::PUBLISHER_QOS_DEFAULT);
  if (impl->publisher == nullptr)
    return Error{Errc::kIo, "ROS 2 topics: cannot create a publisher"};
  const std::string ns = "rt/msgraphs/" + name + "/";
  impl->markers =
      impl->Writer(new visualization_msgs::msg::MarkerArrayPubSubType(), ns + "map_markers");
  impl->cloud = impl->Writer(new sensor_msgs::msg::PointCloud2PubSubType(), ns + "map_cloud");
  impl->path = impl->Writer(new nav_msgs::msg::PathPubSubType(), ns + "trajectory");
  impl->tf = impl->Writer(new tf2_msgs::msg::TFMessagePubSubType(), "rt/tf");
  if (impl->markers == nullptr || impl->cloud == nullptr || impl->path == nullptr ||
      impl->tf == nullptr)
    return Error{Errc::kIo, "ROS 2 topics: cannot create a writer"};
  return std::unique_ptr<RosPublisher>(new RosPublisher(std::move(impl)));
}

bool RosPublisher::cloud_wanted() const {
  dds::PublicationMatchedStatus status;
  impl_->cloud->get_publication_matched_status(status);
  return status.current_count > 0;
}

std::uint64_t RosPublisher::published() const { return impl_->published; }

void RosPublisher::Publish(const RosMapView& view) {
  Impl& m = *impl_;
  const std_msgs::msg::Header header = MakeHeader(view.frame, view.stamp_s);

  // Walls and rooms. DELETEALL first: walls merge and disappear between publications.
  visualization_msgs::msg::MarkerArray array;
  visualization_msgs::msg::Marker clear;
  clear.header(header);
  clear.action(3);  // DELETEALL
  array.markers().push_back(clear);
  std::int32_t id = 0;
  for (const RosMapView::Wall& w : view.walls) {
    const Eigen::Vector2d along = w.b - w.a;
    const double length = along.norm();
    if (!(length > 0.05)) continue;
    visualization_msgs::msg::Marker k;
    k.header(header);
    k.ns("walls/robot" + std::to_string(w.robot));
    k.id(id++);
    k.type(1);  // CUBE
    const Eigen::Vector2d mid = 0.5 * (w.a + w.b);
    const Eigen::Quaterniond q(
        Eigen::AngleAxisd(std::atan2(along.y(), along.x()), Eigen::Vector3d::UnitZ()));
    k.pose(MakePose({mid.x(), mid.y(), w.floor_z_m + 0.5 * kWallHeight_m}, q));
    k.scale().x(length);
    k.scale().y(kWallThickness_m);
    k.scale().z(kWallHeight_m);
    k.color(RobotColour(w.robot, 0.6f));
    array.markers().push_back(std::move(k));
  }
  for (const RosMapView::Room& r : view.rooms) {
    visualization_msgs::msg::Marker k;
    k.header(header);
    k.ns("rooms/robot" + std::to_string(r.robot));
    k.id(id++);
    k.type(3);  // CYLINDER: a flat disc on the floor, as wide as the room
    const Eigen::Quaterniond q(Eigen::AngleAxisd(r.yaw_rad, Eigen::Vector3d::UnitZ()));
    k.pose(MakePose({r.centre.x(), r.centre.y(), r.floor_z_m + 0.05}, q));
    k.scale().x(std::max(r.size_x_m, 0.5));
    k.scale().y(std::max(r.size_y_m, 0.5));  // a corridor has no width: drawn 0.5 m
    k.scale().z(0.1);
    k.color(RobotColour(r.robot, 0.35f));
    visualization_msgs::msg::Marker label = k;
    array.markers().push_back(std::move(k));
    label.id(id++);
    label.type(9);  // TEXT_VIEW_FACING
    label.pose().position().z(r.floor_z_m + 1.0);
    label.scale().z(0.4);
    label.color(RobotColour(r.robot, 1.0f));
    label.text("robot " + std::to_string(r.robot) + " room " + std::to_string(r.id));
    array.markers().push_back(std::move(label));
  }
  m.markers->write(&array);

  nav_msgs::msg::Path path;
  path.header(header);
  for (const RosMapView::Keyframe& k : view.trajectory) {
    geometry_msgs::msg::PoseStamped p;
    p.header(MakeHeader(view.frame, k.stamp_s));
    p.pose_(MakePose(k.T_map_base.translation(), Eigen::Quaterniond(k.T_map_base.linear())));
    path.poses().push_back(std::move(p));
  }
  m.path->write(&path);

  if (!view.cloud.empty()) {
    // 0.2 m voxels across keyframes: overlapping keyframes would repeat the same surfaces.
    std::unordered_set<std::uint64_t> seen;
    std::vector<std::uint8_t> data;
    data.reserve(view.cloud.size() * 12);
    for (const Eigen::Vector3f& p : view.cloud) {
      if (!p.allFinite()) continue;
      const auto cell = [](float v) {
        return static_cast<std::uint64_t>(static_cast<std::int64_t>(std::floor(v / kCloudVoxel_m)) &
                                          0x1FFFFF);
      };
      if (!seen.insert(cell(p.x()) | cell(p.y()) << 21 | cell(p.z()) << 42).second) continue;
      const std::size_t at = data.size();
      data.resize(at + 12);
      std::memcpy(&data[at], p.data(), 12);  // x y z float32, little-endian like the host
    }
    sensor_msgs::msg::PointCloud2 cloud;
    cloud.header(header);
    cloud.height(1);
    cloud.width(static_cast<std::uint32_t>(data.size() / 12));
    const char* names[] = {"x", "y", "z"};
    for (std::uint32_t i = 0; i < 3; ++i) {
      sensor_msgs::msg::PointField f;
      f.name(names[i]);
      f.offset(4 * i);
      f.datatype(7);  // FLOAT32
      f.count(1);
      cloud.fields().push_back(f);
    }
    cloud.is_bigendian(false);
    cloud.point_step(12);
    cloud.row_step(static_cast<std::uint32_t>(data.size()));
    cloud.data(std::move(data));
    cloud.is_dense(true);
    m.cloud->write(&cloud);
  }

  if (view.publish_tf && !view.origins.empty()) {
    tf2_msgs::msg::TFMessage tf;
    for (const RosMapView::Origin& o : view.origins) {
      geometry_msgs::msg::TransformStamped t;
      t.header(header);
      t.child_frame_id(o.frame);
      const Eigen::Vector3d& x = o.T_this_that.translation();
      const Eigen::Quaterniond q(o.T_this_that.linear());
      t.transform_().translation().x(x.x());
      t.transform_().translation().y(x.y());
      t.transform_().translation().z(x.z());
      t.transform_().rotation().x(q.x());
      t.transform_().rotation().y(q.y());
      t.transform_().rotation().z(q.z());
      t.transform_().rotation().w(q.w());
      tf.transforms().push_back(std::move(t));
    }
    m.tf->write(&tf);
  }
  ++m.published;
}

}  // namespace msgraphs::runtime::link
