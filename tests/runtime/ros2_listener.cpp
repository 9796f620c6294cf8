// SPDX-License-Identifier: MIT
// ros2_listener: subscribes like RViz2 would (ROS 2 topic and type names, reliable readers,
// data-sharing off) to one robot's map topics and prints what the latest samples hold:
//   ros2_listener --domain N --robot R --seconds S
// Exits 0 once it has seen walls, rooms, a trajectory, a map cloud and a TF, else 1 after S s.
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <string>
#include <thread>

#include "RosHumblePubSubTypes.h"

namespace fdds = eprosima::fastdds::dds;

namespace {

fdds::DataReader* Reader(fdds::DomainParticipant* p,
                         fdds::Subscriber* s,
                         fdds::TopicDataType* type,
                         const std::string& topic_name) {
  fdds::TypeSupport support(type);
  support.register_type(p);
  fdds::Topic* topic =
      p->create_topic(topic_name, support.get_type_name(), fdds::TOPIC_QOS_DEFAULT);
  fdds::DataReaderQos q = fdds::DATAREADER_QOS_DEFAULT;
  q.reliability().kind = fdds::RELIABLE_RELIABILITY_QOS;  // RViz2's default for markers
  q.durability().kind = fdds::VOLATILE_DURABILITY_QOS;
  q.history().kind = fdds::KEEP_LAST_HISTORY_QOS;
  q.history().depth = 10;
  q.endpoint().history_memory_policy =
      eprosima::fastrtps::rtps::PREALLOCATED_WITH_REALLOC_MEMORY_MODE;
  q.data_sharing().off();
  return s->create_datareader(topic, q);
}

}  // namespace

int main(int argc, char** argv) {
  int domain = 0, robot = 1;
  double seconds = 60;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--domain")
      domain = std::atoi(argv[i + 1]);
    else if (a == "--robot")
      robot = std::atoi(argv[i + 1]);
    else if (a == "--seconds")
      seconds = std::atof(argv[i + 1]);
  }
  fdds::DomainParticipantQos pq = fdds::PARTICIPANT_QOS_DEFAULT;
  pq.name("ros2_listener");
  auto udp = std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>();
  udp->interfaceWhiteList.emplace_back("127.0.0.1");
  pq.transport().user_transports.push_back(udp);
  pq.transport().use_builtin_transports = false;
  auto* factory = fdds::DomainParticipantFactory::get_instance();
  fdds::DomainParticipant* p =
      factory->create_participant(static_cast<fdds::DomainId_t>(domain), pq);
  fdds::Subscriber* s = p->create_subscriber(fdds::SUBSCRIBER_QOS_DEFAULT);
  const std::string ns = "rt/msgraphs/robot" + std::to_string(robot) + "/";
  fdds::DataReader* markers =
      Reader(p, s, new visualization_msgs::msg::MarkerArrayPubSubType(), ns + "map_markers");
  fdds::DataReader* cloud =
      Reader(p, s, new sensor_msgs::msg::PointCloud2PubSubType(), ns + "map_cloud");
  fdds::DataReader* path = Reader(p, s, new nav_msgs::msg::PathPubSubType(), ns + "trajectory");
  fdds::DataReader* tf = Reader(p, s, new tf2_msgs::msg::TFMessagePubSubType(), "rt/tf");
  std::size_t walls = 0, rooms = 0, poses = 0, points = 0, transforms = 0;
  std::string frame, child;
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  bool all = false;
  while (!all && std::chrono::steady_clock::now() < end) {
    fdds::SampleInfo info;
    visualization_msgs::msg::MarkerArray m;
    while (markers->take_next_sample(&m, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      walls = rooms = 0;
      for (const auto& k : m.markers()) {
        walls += k.type() == 1;
        rooms += k.type() == 3;
        if (k.type() == 1) frame = k.header().frame_id();
      }
    }
    nav_msgs::msg::Path pa;
    while (path->take_next_sample(&pa, &info) == ReturnCode_t::RETCODE_OK)
      if (info.valid_data) poses = pa.poses().size();
    sensor_msgs::msg::PointCloud2 c;
    while (cloud->take_next_sample(&c, &info) == ReturnCode_t::RETCODE_OK) {
      if (info.valid_data && c.point_step() == 12 && c.data().size() == std::size_t{c.width()} * 12)
        points = c.width();
    }
    tf2_msgs::msg::TFMessage t;
    while (tf->take_next_sample(&t, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data || t.transforms().empty()) continue;
      transforms = t.transforms().size();
      child = t.transforms()[0].child_frame_id();
    }
    all = walls > 0 && rooms > 0 && poses > 0 && points > 0 && transforms > 0;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  std::printf(
      "ros2_listener: robot %d: %zu walls and %zu rooms in %s, %zu trajectory poses, %zu map "
      "points, "
      "%zu transforms (first child %s)\n",
      robot, walls, rooms, frame.c_str(), poses, points, transforms, child.c_str());
  p->delete_contained_entities();
  factory->delete_participant(p);
  return all ? 0 : 1;
}
