// SPDX-License-Identifier: MIT
// hostile_peer: a DDS participant that sends a msgraphs node everything it must refuse, under
// the fleet's topic and type names: unknown version fields, sender id 0, the node's own id
// from a foreign writer, payloads past the IDL bounds, bytes that do not deserialise, payloads
// whose CRC fails, and a flood. runtime.hostile_samples then checks the node's counters.
//
//   hostile_peer --domain N --target ROBOT [--flood N]
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <string>
#include <thread>
#include <vector>

#include "HostilePubSubTypes.h"

namespace fdds = eprosima::fastdds::dds;

namespace {

fdds::DataWriter* MakeWriter(fdds::DomainParticipant* p,
                             fdds::Publisher* pub,
                             fdds::TopicDataType* type,
                             const char* type_name,
                             const char* topic_name,
                             bool transient_local) {
  type->setName(type_name);  // masquerade as the fleet's type
  fdds::TypeSupport support(type);
  if (support.register_type(p) != ReturnCode_t::RETCODE_OK) return nullptr;
  fdds::Topic* topic = p->create_topic(topic_name, type_name, fdds::TOPIC_QOS_DEFAULT);
  if (topic == nullptr) return nullptr;
  fdds::DataWriterQos q = fdds::DATAWRITER_QOS_DEFAULT;
  q.reliability().kind = fdds::RELIABLE_RELIABILITY_QOS;
  q.reliability().max_blocking_time = {5, 0};
  q.durability().kind =
      transient_local ? fdds::TRANSIENT_LOCAL_DURABILITY_QOS : fdds::VOLATILE_DURABILITY_QOS;
  q.history().kind = fdds::KEEP_ALL_HISTORY_QOS;
  q.endpoint().history_memory_policy = eprosima::fastrtps::rtps::DYNAMIC_REUSABLE_MEMORY_MODE;
  q.data_sharing().off();
  q.publish_mode().kind = fdds::ASYNCHRONOUS_PUBLISH_MODE;  // fragments the 300 kB sample
  return pub->create_datawriter(topic, q);
}

bool WaitMatched(fdds::DataWriter* w) {
  for (int i = 0; i < 200; ++i) {
    fdds::PublicationMatchedStatus s;
    w->get_publication_matched_status(s);
    if (s.current_count > 0) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return false;
}

}  // namespace

int main(int argc, char** argv) {
  int domain = -1, target = 0, flood = 2000;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--domain")
      domain = std::atoi(argv[i + 1]);
    else if (a == "--target")
      target = std::atoi(argv[i + 1]);
    else if (a == "--flood")
      flood = std::atoi(argv[i + 1]);
  }
  if (domain < 0 || target <= 0) {
    std::fprintf(stderr, "usage: hostile_peer --domain N --target ROBOT [--flood N]\n");
    return 2;
  }
  fdds::DomainParticipantQos pq = fdds::PARTICIPANT_QOS_DEFAULT;
  pq.name("hostile");
  auto udp = std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>();
  udp->interfaceWhiteList.emplace_back("127.0.0.1");
  pq.transport().user_transports.push_back(udp);
  pq.transport().use_builtin_transports = false;
  auto* factory = fdds::DomainParticipantFactory::get_instance();
  fdds::DomainParticipant* p =
      factory->create_participant(static_cast<fdds::DomainId_t>(domain), pq);
  if (p == nullptr) return 1;
  fdds::Publisher* pub = p->create_publisher(fdds::PUBLISHER_QOS_DEFAULT);
  fdds::DataWriter* graph =
      MakeWriter(p, pub, new hostile::UnboundedGraphPubSubType(),
                 "msgraphs::link::DistilledGraphSample", "msgraphs/graph", true);
  fdds::DataWriter* request =
      MakeWriter(p, pub, new hostile::UnboundedRequestPubSubType(),
                 "msgraphs::link::RoomCloudRequestSample", "msgraphs/room_cloud_request", false);
  fdds::DataWriter* cloud =
      MakeWriter(p, pub, new hostile::TruncatedPubSubType(), "msgraphs::link::RoomCloudSample",
                 "msgraphs/room_cloud", false);
  if (graph == nullptr || request == nullptr || cloud == nullptr) {
    std::fprintf(stderr, "hostile_peer: cannot create the writers\n");
    return 1;
  }
  if (!WaitMatched(graph) || !WaitMatched(request) || !WaitMatched(cloud)) {
    std::fprintf(stderr, "hostile_peer: the node's readers never matched\n");
    return 1;
  }
  const auto to = static_cast<std::uint16_t>(target);
  int sent = 0;
  auto send_request = [&](std::uint16_t version, std::uint16_t from,
                          std::vector<std::uint8_t> bytes) {
    hostile::UnboundedRequest r;
    r.version(version);
    r.robot_id(from);
    r.addressee(to);
    r.room_id(1);
    r.payload(std::move(bytes));
    sent += request->write(&r) ? 1 : 0;
  };
  send_request(99, 7, std::vector<std::uint8_t>(21, 0));  // unknown version
  send_request(1, 0, std::vector<std::uint8_t>(21, 0));   // sender 0
  send_request(1, to, std::vector<std::uint8_t>(21, 0));  // the node's own id, a foreign writer
  for (int i = 0; i < flood; ++i) {
    // A request's size and magic with garbage inside: the CRC fails in the node's decoder.
    std::vector<std::uint8_t> bytes(21, static_cast<std::uint8_t>(i));
    bytes[0] = 'M', bytes[1] = 'S', bytes[2] = 'R', bytes[3] = 'Q';
    bytes[5] = 7, bytes[6] = 0;  // from: the sample's sender, so that the link lets it through
    bytes[7] = static_cast<std::uint8_t>(to), bytes[8] = static_cast<std::uint8_t>(to >> 8);
    send_request(1, 7, std::move(bytes));
  }
  hostile::UnboundedGraph g;
  g.version(1);
  g.robot_id(7);
  g.graph_version(1);
  g.payload(std::vector<std::uint8_t>(300000, 0xAB));  // past the 262,144-byte bound
  sent += graph->write(&g) ? 1 : 0;
  std::vector<std::uint8_t> garbage(64, 0xCD);  // the sender's id where the codec has it, and
  garbage[6] = 7;                               // garbage elsewhere: the link lets it through,
  garbage[7] = 0;                               // the decoder's CRC check refuses it
  g.payload(garbage);
  sent += graph->write(&g) ? 1 : 0;
  g.payload(std::vector<std::uint8_t>(64, 0xCD));  // a sender inside that is not the sample's
  sent += graph->write(&g) ? 1 : 0;
  hostile::Truncated t;
  t.version(1);
  sent += cloud->write(&t) ? 1 : 0;  // cannot deserialise as a RoomCloudSample
  for (fdds::DataWriter* w : {graph, request, cloud}) w->wait_for_acknowledgments({20, 0});
  std::printf("hostile_peer: %d hostile samples sent and acknowledged\n", sent);
  p->delete_contained_entities();
  factory->delete_participant(p);
  return 0;
}
