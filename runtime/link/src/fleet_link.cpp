// SPDX-License-Identifier: MIT
#include "msgraphs/runtime/link/fleet_link.hpp"

#include <fastdds/rtps/attributes/ServerAttributes.h>
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastrtps/attributes/LibrarySettingsAttributes.h>
#include <fastrtps/xmlparser/XMLProfileManager.h>

#include <atomic>
#include <condition_variable>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <fastdds/rtps/flowcontrol/FlowControllerDescriptor.hpp>
#include <map>
#include <mutex>

#include "CollabMessagesPubSubTypes.h"
#include "TelemetryPubSubTypes.h"
#include "msgraphs/base/byte_order.hpp"
#include "msgraphs/core/collab/free_space_codec.hpp"
#include "msgraphs/platform/clock.hpp"

namespace msgraphs::runtime::link {

namespace dds = eprosima::fastdds::dds;
namespace rtps = eprosima::fastrtps::rtps;
namespace idl = msgraphs::link;

namespace {

constexpr int kTelemetry = core::kCollabMessageTypes;  // index of the telemetry topic's stats
constexpr const char* kTopicNames[core::kCollabMessageTypes + 1] = {
    "msgraphs/graph", "msgraphs/room_descriptor", "msgraphs/room_cloud_request",
    "msgraphs/room_cloud", "msgraphs/free_space", "msgraphs/place_request", "msgraphs/place_cloud",
    "msgraphs/telemetry"};
// Flow controller priorities (-10 highest): liveness first, then what unblocks a peer's
// matching, then state, then bulk.
constexpr const char* kPriorities[core::kCollabMessageTypes + 1] = {"0", "2", "-5", "5", "3", "-5", "5", "-10"};
constexpr int kFreeSpaceTopic = static_cast<int>(core::CollabMessageType::kFreeSpace);
constexpr int kPlaceRequestTopic = static_cast<int>(core::CollabMessageType::kPlaceRequest);
constexpr int kPlaceCloudTopic = static_cast<int>(core::CollabMessageType::kPlaceCloud);
constexpr const char* kFlowController = "msgraphs_radio";
constexpr const char* kParticipantPrefix = "msgraphs_robot_";

eprosima::fastrtps::Duration_t ToDds(double seconds) {
  const auto ns = static_cast<std::int64_t>(seconds * 1e9);
  return eprosima::fastrtps::Duration_t(static_cast<std::int32_t>(ns / 1000000000),
                                        static_cast<std::uint32_t>(ns % 1000000000));
}

// The generated type, counting samples whose bytes do not deserialise (Fast DDS drops them
// without telling the reader). Catches everything Fast CDR may throw on hostile bytes.
template <typename Generated>
class CountingType final : public Generated {
 public:
  explicit CountingType(std::atomic<std::uint64_t>* failures) : failures_(failures) {}
  bool deserialize(rtps::SerializedPayload_t* payload, void* data) override {
    bool ok = false;
    try {
      ok = Generated::deserialize(payload, data);
    } catch (...) {
      ok = false;
    }
    if (!ok) failures_->fetch_add(1, std::memory_order_relaxed);
    return ok;
  }

 private:
  std::atomic<std::uint64_t>* failures_;
};

std::uint16_t RobotFromParticipantName(const std::string& name) {
  const std::string prefix = kParticipantPrefix;
  if (name.compare(0, prefix.size(), prefix) != 0) return 0;
  const long id = std::strtol(name.c_str() + prefix.size(), nullptr, 10);
  return id > 0 && id <= 65535 ? static_cast<std::uint16_t>(id) : 0;
}

dds::DomainParticipantQos MakeParticipantQos(RobotId self, const LinkSettings& link) {
  const DdsSettings& settings = link.dds;
  dds::DomainParticipantQos qos = dds::PARTICIPANT_QOS_DEFAULT;
  qos.name(kParticipantPrefix + std::to_string(self.value));
  // UDP only, always: SHM would bypass the network (and every injected fault), and a robot's
  // peers are on other computers anyway.
  auto udp = std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>();
  udp->sendBufferSize = 1 << 20;
  udp->receiveBufferSize = 4 << 20;
  if (settings.loopback_only) {
    udp->interfaceWhiteList.emplace_back("127.0.0.1");
  } else {
    for (const std::string& address : settings.interfaces)
      udp->interfaceWhiteList.push_back(address);
  }
  qos.transport().user_transports.push_back(udp);
  qos.transport().use_builtin_transports = false;

  auto& builtin = qos.wire_protocol().builtin;
  builtin.discovery_config.leaseDuration = ToDds(settings.lease_duration_s);
  builtin.discovery_config.leaseDuration_announcementperiod =
      ToDds(settings.lease_duration_s / 5.0);
  for (const std::string& peer : settings.initial_peers) {
    rtps::Locator_t locator;
    rtps::IPLocator::setIPv4(locator, peer);
    locator.port = 0;  // 0: the well-known ports of participant ids 0..3 are tried
    builtin.initialPeersList.push_back(locator);
  }
  if (settings.discovery == Discovery::kUnicast) {
    // No multicast: an empty locator means "every interface, well-known unicast port".
    builtin.metatrafficUnicastLocatorList.push_back(rtps::Locator_t());
  } else if (settings.discovery == Discovery::kServer) {
    std::string address;
    std::uint16_t port = 0;
    ParseIpv4Endpoint(settings.discovery_server, address, port);
    builtin.discovery_config.discoveryProtocol = rtps::DiscoveryProtocol_t::CLIENT;
    eprosima::fastdds::rtps::RemoteServerAttributes server;
    eprosima::fastdds::rtps::get_server_client_default_guidPrefix(
        static_cast<int>(settings.discovery_server_id), server.guidPrefix);
    rtps::Locator_t locator;
    rtps::IPLocator::setIPv4(locator, address);
    locator.port = port;
    server.metatrafficUnicastLocatorList.push_back(locator);
    builtin.discovery_config.m_DiscoveryServers.push_back(server);
  }
  if (link.max_bytes_per_s > 0) {
    auto flow = std::make_shared<eprosima::fastdds::rtps::FlowControllerDescriptor>();
    flow->name = kFlowController;
    flow->scheduler = eprosima::fastdds::rtps::FlowControllerSchedulerPolicy::HIGH_PRIORITY;
    // 10 periods a second: a large room cloud is spread out instead of sent in one burst.
    flow->period_ms = 100;
    flow->max_bytes_per_period =
        static_cast<std::int32_t>(std::max<std::uint32_t>(link.max_bytes_per_s / 10, 1500));
    qos.flow_controllers().push_back(flow);
  }
  return qos;
}

}  // namespace

void DisableIntraprocessDelivery() {
  eprosima::fastrtps::LibrarySettingsAttributes settings;
  settings.intraprocess_delivery = eprosima::fastrtps::INTRAPROCESS_OFF;
  eprosima::fastrtps::xmlparser::XMLProfileManager::library_settings(settings);
}

const char* ToString(NodeState state) {
  switch (state) {
    case NodeState::kStarting:
      return "starting";
    case NodeState::kMapping:
      return "mapping";
    case NodeState::kInputDone:
      return "input done";
    case NodeState::kStopping:
      return "stopping";
  }
  return "?";
}

struct FleetLink::Impl final : dds::DomainParticipantListener {
  RobotId self;
  LinkSettings settings;
  std::array<std::atomic<std::uint64_t>, core::kCollabMessageTypes + 1> undecodable{};

  mutable std::mutex mutex;  // stats, peers, the wake-up flag
  std::condition_variable data_ready;
  bool pending = false;
  LinkStats stats;
  std::map<std::uint16_t, PeerView> peers;
  std::uint32_t telemetry_counter = 0;
  int next_reader = 0;

  dds::DomainParticipant* participant = nullptr;
  std::array<dds::TypeSupport, core::kCollabMessageTypes + 1> types;
  std::array<dds::DataWriter*, core::kCollabMessageTypes + 1> writers{};
  std::array<dds::DataReader*, core::kCollabMessageTypes + 1> readers{};
  dds::Publisher* publisher = nullptr;
  dds::Subscriber* subscriber = nullptr;
  std::mutex write_mutex;  // one sample object per topic, reused by Send
  idl::DistilledGraphSample out_graph, in_graph;
  idl::RoomDescriptorSample out_descriptor, in_descriptor;
  idl::RoomCloudRequestSample out_request, in_request;
  idl::RoomCloudSample out_cloud, in_cloud;
  idl::FreeSpaceSample out_free, in_free;
  idl::PlaceRequestSample out_place_request, in_place_request;
  idl::PlaceCloudSample out_place_cloud, in_place_cloud;

  ~Impl() override {
    if (participant == nullptr) return;
    participant->delete_contained_entities();
    dds::DomainParticipantFactory::get_instance()->delete_participant(participant);
  }

  int TopicOf(const dds::DataReader* reader) const {
    for (int t = 0; t <= kTelemetry; ++t)
      if (readers[static_cast<std::size_t>(t)] == reader) return t;
    return -1;
  }

  void on_data_available(dds::DataReader* reader) override {
    if (reader == readers[kTelemetry]) {
      TakeTelemetry();
      return;
    }
    {
      std::lock_guard<std::mutex> lock(mutex);
      pending = true;
    }
    data_ready.notify_one();
  }
  void on_sample_lost(dds::DataReader* reader, const dds::SampleLostStatus& status) override {
    const int t = TopicOf(reader);
    if (t < 0) return;
    std::lock_guard<std::mutex> lock(mutex);
    stats.topics[static_cast<std::size_t>(t)].lost = static_cast<std::uint64_t>(status.total_count);
  }
  void on_participant_discovery(dds::DomainParticipant*,
                                rtps::ParticipantDiscoveryInfo&& info) override {
    const std::uint16_t robot = RobotFromParticipantName(info.info.m_participantName.to_string());
    if (robot == 0 || robot == self.value) return;
    std::lock_guard<std::mutex> lock(mutex);
    PeerView& peer = peers[robot];
    peer.telemetry.robot = RobotId{robot};
    if (info.status == rtps::ParticipantDiscoveryInfo::DISCOVERED_PARTICIPANT) {
      peer.alive = true;
      ++stats.robots_appeared;
    } else if (info.status == rtps::ParticipantDiscoveryInfo::REMOVED_PARTICIPANT ||
               info.status == rtps::ParticipantDiscoveryInfo::DROPPED_PARTICIPANT) {
      if (peer.alive) ++stats.robots_vanished;
      peer.alive = false;
    }
  }

  void TakeTelemetry() {
    idl::Telemetry msg;
    dds::SampleInfo info;
    while (readers[kTelemetry]->take_next_sample(&msg, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      std::lock_guard<std::mutex> lock(mutex);
      TopicStats& s = stats.topics[kTelemetry];
      if (info.sample_identity.writer_guid() == writers[kTelemetry]->guid()) continue;  // ours
      if (msg.version() != idl::kTelemetryVersion) {
        ++s.rejected_version;
        continue;
      }
      if (msg.robot_id() == 0 || msg.robot_id() == self.value ||
          msg.state() > idl::kStateStopping) {
        ++s.rejected_sender;
        continue;
      }
      ++s.received;
      PeerView& peer = peers[msg.robot_id()];
      Telemetry& t = peer.telemetry;
      t.robot = RobotId{msg.robot_id()};
      t.counter = msg.counter();
      t.stamp = UnixTime::FromNanoseconds(static_cast<std::int64_t>(msg.stamp_unix_ns()));
      t.uptime = Duration::FromNanoseconds(static_cast<std::int64_t>(msg.uptime_ns()));
      t.build = msg.build().to_string();
      t.state = static_cast<NodeState>(msg.state());
      t.keyframes = msg.keyframes();
      t.walls = msg.walls();
      t.rooms = msg.rooms();
      t.graph_version = msg.graph_version();
      t.bytes_sent = msg.bytes_sent();
      t.bytes_received = msg.bytes_received();
      t.merged.clear();
      for (std::uint16_t r : msg.merged())
        if (!t.merged.full()) t.merged.push_back(r);
      t.resync_from.clear();
      for (std::uint16_t r : msg.resync_from())
        if (!t.resync_from.full()) t.resync_from.push_back(r);
      peer.heard = platform::SteadyNow();
      peer.has_telemetry = true;
      peer.alive = true;
    }
  }

  // Checks the common fields of a received sample; true when the node should see it.
  bool Admit(int t,
             const dds::SampleInfo& info,
             std::uint16_t version,
             std::uint16_t from,
             std::uint16_t to,
             const std::vector<std::uint8_t>& payload) {
    const std::size_t bytes = payload.size();
    std::lock_guard<std::mutex> lock(mutex);
    TopicStats& s = stats.topics[static_cast<std::size_t>(t)];
    if (info.sample_identity.writer_guid() == writers[static_cast<std::size_t>(t)]->guid())
      return false;  // our own writer, same topic
    if (from == self.value) {
      ++s.rejected_sender;  // someone else using our robot id
      return false;
    }
    if (version != idl::kCollabVersion) {
      ++s.rejected_version;
      return false;
    }
    if (from == 0) {
      ++s.rejected_sender;
      return false;
    }
    if (to != 0 && to != self.value) {
      ++s.not_for_us;
      return false;
    }
    if (bytes > settings.max_payload_bytes[static_cast<std::size_t>(t)]) {
      ++s.rejected_oversize;
      return false;
    }
    // The sample's sender must be the one inside the message (where the header is long enough
    // to say; a shorter one is left to the decoder). Offsets: the codecs' headers.
    const std::size_t sender_at = t == 0 ? 6 : t == 3 ? 6 : 5;
    if (bytes >= sender_at + 2 && ReadU16Le(&payload[sender_at]) != from) {
      ++s.rejected_sender;
      return false;
    }
    ++s.received;
    s.received_bytes += bytes;
    return true;
  }

  // Takes one sample of topic t into `out`; false when that reader had nothing for us.
  bool TakeOne(int t, InboundMessage& out) {
    dds::SampleInfo info;
    auto copy = [&](const std::vector<std::uint8_t>& payload) {
      out.bytes.assign(payload.begin(), payload.end());
    };
    dds::DataReader* reader = readers[static_cast<std::size_t>(t)];
    for (;;) {
      bool admitted = false;
      switch (static_cast<core::CollabMessageType>(t)) {
        case core::CollabMessageType::kDistilledGraph:
          if (reader->take_next_sample(&in_graph, &info) != ReturnCode_t::RETCODE_OK) return false;
          if (!info.valid_data) continue;
          admitted = Admit(t, info, in_graph.version(), in_graph.robot_id(), 0, in_graph.payload());
          if (admitted) {
            copy(in_graph.payload());
            out.from = in_graph.robot_id();
            out.to = 0;
          }
          break;
        case core::CollabMessageType::kRoomDescriptor:
          if (reader->take_next_sample(&in_descriptor, &info) != ReturnCode_t::RETCODE_OK)
            return false;
          if (!info.valid_data) continue;
          admitted = Admit(t, info, in_descriptor.version(), in_descriptor.robot_id(), 0,
                           in_descriptor.payload());
          if (admitted) {
            copy(in_descriptor.payload());
            out.from = in_descriptor.robot_id();
            out.to = 0;
          }
          break;
        case core::CollabMessageType::kRoomCloudRequest:
          if (reader->take_next_sample(&in_request, &info) != ReturnCode_t::RETCODE_OK)
            return false;
          if (!info.valid_data) continue;
          admitted = Admit(t, info, in_request.version(), in_request.robot_id(),
                           in_request.addressee(), in_request.payload());
          if (admitted) {
            copy(in_request.payload());
            out.from = in_request.robot_id();
            out.to = in_request.addressee();
          }
          break;
        case core::CollabMessageType::kRoomCloud:
          if (reader->take_next_sample(&in_cloud, &info) != ReturnCode_t::RETCODE_OK) return false;
          if (!info.valid_data) continue;
          admitted = Admit(t, info, in_cloud.version(), in_cloud.robot_id(), in_cloud.addressee(),
                           in_cloud.payload());
          if (admitted) {
            copy(in_cloud.payload());
            out.from = in_cloud.robot_id();
            out.to = in_cloud.addressee();
          }
          break;
        case core::CollabMessageType::kPlaceRequest:
          if (reader->take_next_sample(&in_place_request, &info) != ReturnCode_t::RETCODE_OK) return false;
          if (!info.valid_data) continue;
          admitted = Admit(t, info, in_place_request.version(), in_place_request.robot_id(),
                           in_place_request.addressee(), in_place_request.payload());
          if (admitted) {
            copy(in_place_request.payload());
            out.from = in_place_request.robot_id();
            out.to = in_place_request.addressee();
          }
          break;
        case core::CollabMessageType::kPlaceCloud:
          if (reader->take_next_sample(&in_place_cloud, &info) != ReturnCode_t::RETCODE_OK) return false;
          if (!info.valid_data) continue;
          admitted = Admit(t, info, in_place_cloud.version(), in_place_cloud.robot_id(),
                           in_place_cloud.addressee(), in_place_cloud.payload());
          if (admitted) {
            copy(in_place_cloud.payload());
            out.from = in_place_cloud.robot_id();
            out.to = in_place_cloud.addressee();
          }
          break;
        case core::CollabMessageType::kFreeSpace:
          if (reader->take_next_sample(&in_free, &info) != ReturnCode_t::RETCODE_OK) return false;
          if (!info.valid_data) continue;
          admitted = Admit(t, info, in_free.version(), in_free.robot_id(), 0, in_free.payload());
          if (admitted) {
            copy(in_free.payload());
            out.from = in_free.robot_id();
            out.to = 0;
          }
          break;
      }
      if (admitted) {
        out.type = static_cast<core::CollabMessageType>(t);
        return true;
      }
    }
  }
};

FleetLink::FleetLink(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

FleetLink::~FleetLink() = default;

Expected<std::unique_ptr<FleetLink>> FleetLink::Create(RobotId self, const LinkSettings& settings) {
  if (!self.valid()) return Error{Errc::kInvalidConfig, "robot id 0 is reserved"};
  if (Status valid = settings.Validate(); !valid) return valid.error();

  auto impl = std::make_unique<Impl>();
  impl->self = self;
  impl->settings = settings;
  auto* factory = dds::DomainParticipantFactory::get_instance();
  dds::StatusMask participant_mask = dds::StatusMask::none();  // discovery callbacks only
  impl->participant = factory->create_participant(
      settings.dds.domain_id, MakeParticipantQos(self, settings), impl.get(), participant_mask);
  if (impl->participant == nullptr) return Error{Errc::kIo, "cannot create DDS participant"};

  impl->types[0] = dds::TypeSupport(
      new CountingType<idl::DistilledGraphSamplePubSubType>(&impl->undecodable[0]));
  impl->types[1] = dds::TypeSupport(
      new CountingType<idl::RoomDescriptorSamplePubSubType>(&impl->undecodable[1]));
  impl->types[2] = dds::TypeSupport(
      new CountingType<idl::RoomCloudRequestSamplePubSubType>(&impl->undecodable[2]));
  impl->types[3] =
      dds::TypeSupport(new CountingType<idl::RoomCloudSamplePubSubType>(&impl->undecodable[3]));
  impl->types[kFreeSpaceTopic] =
      dds::TypeSupport(new CountingType<idl::FreeSpaceSamplePubSubType>(&impl->undecodable[kFreeSpaceTopic]));
  impl->types[kPlaceRequestTopic] = dds::TypeSupport(
      new CountingType<idl::PlaceRequestSamplePubSubType>(&impl->undecodable[kPlaceRequestTopic]));
  impl->types[kPlaceCloudTopic] = dds::TypeSupport(
      new CountingType<idl::PlaceCloudSamplePubSubType>(&impl->undecodable[kPlaceCloudTopic]));
  impl->types[kTelemetry] =
      dds::TypeSupport(new CountingType<idl::TelemetryPubSubType>(&impl->undecodable[kTelemetry]));
  impl->publisher = impl->participant->create_publisher(dds::PUBLISHER_QOS_DEFAULT);
  impl->subscriber = impl->participant->create_subscriber(dds::SUBSCRIBER_QOS_DEFAULT);
  if (impl->publisher == nullptr || impl->subscriber == nullptr)
    return Error{Errc::kIo, "cannot create DDS publisher or subscriber"};

  for (int t = 0; t <= kTelemetry; ++t) {
    const auto i = static_cast<std::size_t>(t);
    if (impl->types[i].register_type(impl->participant) != ReturnCode_t::RETCODE_OK)
      return Error{Errc::kIo, "cannot register a DDS type"};
    dds::Topic* topic = impl->participant->create_topic(
        kTopicNames[i], impl->types[i].get_type_name(), dds::TOPIC_QOS_DEFAULT);
    if (topic == nullptr) return Error{Errc::kIo, "cannot create a DDS topic"};

    const bool state = t == 0 || t == 1 || t == kFreeSpaceTopic || t == kTelemetry;  // late joiners need it
    dds::DataWriterQos w = dds::DATAWRITER_QOS_DEFAULT;
    w.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
    w.reliability().max_blocking_time = ToDds(0.1);
    // Repairs follow the writer's heartbeat: 0.5 s instead of the default 3 s keeps a lossy
    // radio's retransmissions prompt for a few dozen bytes a second per reader.
    w.reliable_writer_qos().times.heartbeatPeriod = ToDds(0.5);
    w.durability().kind =
        state ? dds::TRANSIENT_LOCAL_DURABILITY_QOS : dds::VOLATILE_DURABILITY_QOS;
    w.history().kind = dds::KEEP_LAST_HISTORY_QOS;
    w.history().depth = t == 0   ? static_cast<std::int32_t>(settings.graph_history)
                        : t == 2 || t == kPlaceRequestTopic ? 16
                        : t == 3 || t == kPlaceCloudTopic   ? 8
                                 : 1;
    // Descriptors: one instance per own room; telemetry, graph and free space: one instance
    // (this robot).
    w.resource_limits().max_instances = t == 1 ? 256 : 1;
    w.resource_limits().max_samples_per_instance = w.history().depth;
    w.resource_limits().max_samples = w.resource_limits().max_instances * w.history().depth;
    // Payloads up to 1 MiB: allocate what each sample needs, not the IDL bound up front.
    w.endpoint().history_memory_policy = rtps::DYNAMIC_REUSABLE_MEMORY_MODE;
    w.data_sharing().off();
    w.publish_mode().kind = dds::ASYNCHRONOUS_PUBLISH_MODE;
    if (settings.max_bytes_per_s > 0) {
      w.publish_mode().flow_controller_name = kFlowController;
      w.properties().properties().emplace_back("fastdds.sfc.priority", kPriorities[i]);
    }
    impl->writers[i] = impl->publisher->create_datawriter(topic, w);

    dds::DataReaderQos r = dds::DATAREADER_QOS_DEFAULT;
    r.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
    r.durability().kind =
        state ? dds::TRANSIENT_LOCAL_DURABILITY_QOS : dds::VOLATILE_DURABILITY_QOS;
    if (t == kTelemetry) {
      r.history().kind = dds::KEEP_LAST_HISTORY_QOS;
      r.history().depth = 4;
      r.resource_limits().max_instances = 64;
      r.resource_limits().max_samples_per_instance = 4;
      r.resource_limits().max_samples = 256;
    } else {
      // Keep-all: a full reader holds the writer back (reliable) rather than lose samples.
      // Keyed topics bound each robot (graph) or room (descriptor) separately; DDS requires
      // max_samples >= max_instances x max_samples_per_instance.
      r.history().kind = dds::KEEP_ALL_HISTORY_QOS;
      const std::int32_t depth = static_cast<std::int32_t>(settings.reader_depth);
      const std::int32_t instances = t == 0 || t == kFreeSpaceTopic ? 32 : t == 1 ? 4096 : 1;
      const std::int32_t per_instance = t == 0 ? std::min(depth, 64) : t == 1 || t == kFreeSpaceTopic ? 2 : depth;
      r.resource_limits().max_instances = instances;
      r.resource_limits().max_samples_per_instance = per_instance;
      r.resource_limits().max_samples = instances * per_instance;
    }
    r.endpoint().history_memory_policy = rtps::DYNAMIC_REUSABLE_MEMORY_MODE;
    r.data_sharing().off();
    dds::StatusMask mask = dds::StatusMask::data_available() << dds::StatusMask::sample_lost();
    impl->readers[i] = impl->subscriber->create_datareader(topic, r, impl.get(), mask);
    if (impl->writers[i] == nullptr || impl->readers[i] == nullptr)
      return Error{Errc::kIo, "cannot create a DDS writer or reader"};
  }
  // Own samples carry our id; readers drop them (Admit), they never reach the node.
  const std::uint16_t id = self.value;
  impl->out_graph.robot_id(id);
  impl->out_descriptor.robot_id(id);
  impl->out_request.robot_id(id);
  impl->out_cloud.robot_id(id);
  impl->out_free.robot_id(id);
  impl->out_place_request.robot_id(id);
  impl->out_place_cloud.robot_id(id);
  return std::unique_ptr<FleetLink>(new FleetLink(std::move(impl)));
}

void FleetLink::Send(core::CollabMessageType type,
                     std::uint16_t to,
                     std::span<const std::uint8_t> bytes) {
  Impl& m = *impl_;
  const auto t = static_cast<std::size_t>(type);
  bool ok = false;
  {
    std::lock_guard<std::mutex> lock(m.write_mutex);
    auto fill = [&](auto& sample) {
      sample.version(idl::kCollabVersion);
      sample.payload().assign(bytes.begin(), bytes.end());
    };
    switch (type) {
      case core::CollabMessageType::kDistilledGraph: {
        fill(m.out_graph);
        // The codec's header (distilled_codec.hpp): version at byte 8, since at byte 12.
        auto u32 = [&](std::size_t at) {
          return at + 4 <= bytes.size() ? ReadU32Le(&bytes[at]) : 0u;
        };
        m.out_graph.graph_version(u32(8));
        m.out_graph.since(u32(12));
        ok = m.writers[t]->write(&m.out_graph);
        break;
      }
      case core::CollabMessageType::kRoomDescriptor: {
        fill(m.out_descriptor);
        auto header = core::PeekRoomDescriptorHeader(bytes);
        m.out_descriptor.room_id(header ? header->room : 0);
        m.out_descriptor.room_version(header ? header->version : 0);
        ok = m.writers[t]->write(&m.out_descriptor);
        break;
      }
      case core::CollabMessageType::kRoomCloudRequest: {
        fill(m.out_request);
        auto request = core::DecodeRoomCloudRequest(bytes);
        m.out_request.addressee(to);
        m.out_request.room_id(request ? request->room : 0);
        ok = m.writers[t]->write(&m.out_request);
        break;
      }
      case core::CollabMessageType::kRoomCloud: {
        fill(m.out_cloud);
        m.out_cloud.addressee(to);
        auto header = core::PeekRoomCloudHeader(bytes);
        m.out_cloud.room_id(header ? header->room : 0);
        ok = m.writers[t]->write(&m.out_cloud);
        break;
      }
      case core::CollabMessageType::kPlaceRequest:
        fill(m.out_place_request);
        m.out_place_request.addressee(to);
        ok = m.writers[t]->write(&m.out_place_request);
        break;
      case core::CollabMessageType::kPlaceCloud:
        fill(m.out_place_cloud);
        m.out_place_cloud.addressee(to);
        ok = m.writers[t]->write(&m.out_place_cloud);
        break;
      case core::CollabMessageType::kFreeSpace: {
        fill(m.out_free);
        auto header = core::PeekFreeSpaceHeader(bytes);
        m.out_free.space_version(header ? header->version : 0);
        ok = m.writers[t]->write(&m.out_free);
        break;
      }
    }
  }
  std::lock_guard<std::mutex> lock(m.mutex);
  TopicStats& s = m.stats.topics[t];
  if (ok) {
    ++s.sent;
    s.sent_bytes += bytes.size();
  } else {
    ++s.write_failures;
  }
}

bool FleetLink::Receive(InboundMessage& out, Duration timeout) {
  Impl& m = *impl_;
  const SteadyTime deadline = platform::SteadyNow() + timeout;
  for (;;) {
    {
      std::lock_guard<std::mutex> lock(m.mutex);
      m.pending = false;
    }
    // Round-robin over the topics so that a flood on one cannot starve the others.
    for (int k = 0; k < core::kCollabMessageTypes; ++k) {
      const int t = (m.next_reader + k) % core::kCollabMessageTypes;
      if (m.TakeOne(t, out)) {
        m.next_reader = (t + 1) % core::kCollabMessageTypes;
        std::lock_guard<std::mutex> lock(m.mutex);
        m.pending = true;  // there may be more
        return true;
      }
    }
    std::unique_lock<std::mutex> lock(m.mutex);
    const Duration left = deadline - platform::SteadyNow();
    if (left <= Duration()) return false;
    m.data_ready.wait_for(lock, std::chrono::nanoseconds(left.nanoseconds()),
                          [&] { return m.pending; });
    if (!m.pending) return false;
  }
}

Status FleetLink::PublishTelemetry(Telemetry telemetry) {
  Impl& m = *impl_;
  idl::Telemetry msg;
  msg.version(idl::kTelemetryVersion);
  msg.robot_id(m.self.value);
  msg.counter(m.telemetry_counter++);
  msg.stamp_unix_ns(static_cast<std::uint64_t>(telemetry.stamp.nanoseconds_since_epoch()));
  msg.uptime_ns(static_cast<std::uint64_t>(telemetry.uptime.nanoseconds()));
  msg.build(telemetry.build.substr(0, 64));
  msg.state(static_cast<std::uint8_t>(telemetry.state));
  msg.keyframes(telemetry.keyframes);
  msg.walls(telemetry.walls);
  msg.rooms(telemetry.rooms);
  msg.graph_version(telemetry.graph_version);
  msg.bytes_sent(telemetry.bytes_sent);
  msg.bytes_received(telemetry.bytes_received);
  msg.merged().assign(telemetry.merged.begin(), telemetry.merged.end());
  msg.resync_from().assign(telemetry.resync_from.begin(), telemetry.resync_from.end());
  const bool ok = m.writers[kTelemetry]->write(&msg);
  std::lock_guard<std::mutex> lock(m.mutex);
  if (!ok) {
    ++m.stats.topics[kTelemetry].write_failures;
    return Error{Errc::kWouldBlock, "telemetry write refused"};
  }
  ++m.stats.topics[kTelemetry].sent;
  return Ok();
}

std::vector<FleetLink::PeerView> FleetLink::Peers() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  std::vector<PeerView> out;
  for (const auto& [robot, view] : impl_->peers) out.push_back(view);
  return out;
}

void* FleetLink::participant() const { return impl_->participant; }

int FleetLink::matched_readers() const {
  dds::PublicationMatchedStatus status;
  impl_->writers[kTelemetry]->get_publication_matched_status(status);
  return status.current_count;
}

LinkStats FleetLink::stats() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  LinkStats out = impl_->stats;
  for (std::size_t t = 0; t < out.topics.size(); ++t)
    out.topics[t].undecodable = impl_->undecodable[t].load(std::memory_order_relaxed);
  return out;
}

}  // namespace msgraphs::runtime::link
