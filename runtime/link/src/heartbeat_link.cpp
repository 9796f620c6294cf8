// SPDX-License-Identifier: MIT
#include "msgraphs/runtime/link/heartbeat_link.hpp"

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>

#include "HeartbeatPubSubTypes.h"
#include "msgraphs/platform/clock.hpp"

namespace msgraphs::runtime::link {

namespace dds = eprosima::fastdds::dds;
namespace rtps = eprosima::fastrtps::rtps;

namespace {

constexpr const char* kTopicName = "msgraphs/heartbeat";

eprosima::fastrtps::Duration_t ToDds(Duration d) {
  const std::int64_t ns = d.nanoseconds() < 0 ? 0 : d.nanoseconds();
  return eprosima::fastrtps::Duration_t(static_cast<std::int32_t>(ns / 1000000000),
                         static_cast<std::uint32_t>(ns % 1000000000));
}

dds::DomainParticipantQos MakeParticipantQos(RobotId self, const DdsSettings& settings) {
  dds::DomainParticipantQos qos = dds::PARTICIPANT_QOS_DEFAULT;
  qos.name("msgraphs_robot_" + std::to_string(self.value));
  if (settings.loopback_only) {
    // UDP on 127.0.0.1 only: no SHM (it bypasses network impairment tests) and no multicast
    // on real interfaces (it would leave this machine).
    auto udp = std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>();
    udp->interfaceWhiteList.emplace_back("127.0.0.1");
    qos.transport().user_transports.push_back(udp);
    qos.transport().use_builtin_transports = false;
  }
  for (const std::string& peer : settings.initial_peers) {
    rtps::Locator_t locator;
    rtps::IPLocator::setIPv4(locator, peer);
    locator.port = 0;  // 0: Fast DDS tries the well-known ports of participant ids 0..N
    qos.wire_protocol().builtin.initialPeersList.push_back(locator);
  }
  return qos;
}

}  // namespace

struct HeartbeatLink::Impl {
  RobotId self;
  std::string build_label;
  std::uint32_t next_sequence = 0;
  HeartbeatStats stats;
  dds::DomainParticipant* participant = nullptr;
  dds::TypeSupport type{new msgraphs::link::HeartbeatPubSubType()};
  dds::Topic* topic = nullptr;
  dds::Publisher* publisher = nullptr;
  dds::Subscriber* subscriber = nullptr;
  dds::DataWriter* writer = nullptr;
  dds::DataReader* reader = nullptr;

  ~Impl() {
    if (participant == nullptr) return;
    participant->delete_contained_entities();
    dds::DomainParticipantFactory::get_instance()->delete_participant(participant);
  }
};

HeartbeatLink::HeartbeatLink(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
HeartbeatLink::~HeartbeatLink() = default;

Expected<std::unique_ptr<HeartbeatLink>> HeartbeatLink::Create(RobotId self,
                                                               const DdsSettings& settings,
                                                               const std::string& build_label) {
  if (!self.valid()) return Error{Errc::kInvalidConfig, "robot id 0 is reserved"};
  if (Status valid = Validate(settings); !valid) return valid.error();

  auto impl = std::make_unique<Impl>();
  impl->self = self;
  impl->build_label = build_label.substr(0, 64);
  impl->participant = dds::DomainParticipantFactory::get_instance()->create_participant(
      settings.domain_id, MakeParticipantQos(self, settings));
  if (impl->participant == nullptr) return Error{Errc::kIo, "cannot create DDS participant"};
  if (impl->type.register_type(impl->participant) != ReturnCode_t::RETCODE_OK) {
    return Error{Errc::kIo, "cannot register Heartbeat type"};
  }
  impl->topic = impl->participant->create_topic(kTopicName, impl->type.get_type_name(),
                                                dds::TOPIC_QOS_DEFAULT);
  impl->publisher = impl->participant->create_publisher(dds::PUBLISHER_QOS_DEFAULT);
  impl->subscriber = impl->participant->create_subscriber(dds::SUBSCRIBER_QOS_DEFAULT);
  if (impl->topic == nullptr || impl->publisher == nullptr || impl->subscriber == nullptr) {
    return Error{Errc::kIo, "cannot create DDS topic, publisher or subscriber"};
  }

  // Latest state per robot: reliable + transient-local, keep-last 1 on the writer; the reader
  // keeps a few per writer so a burst from several robots is not overwritten unread.
  dds::DataWriterQos wqos = dds::DATAWRITER_QOS_DEFAULT;
  wqos.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
  wqos.reliability().max_blocking_time = ToDds(Duration::FromMilliseconds(100));
  wqos.durability().kind = dds::TRANSIENT_LOCAL_DURABILITY_QOS;
  wqos.history().kind = dds::KEEP_LAST_HISTORY_QOS;
  wqos.history().depth = 1;
  wqos.data_sharing().off();
  dds::DataReaderQos rqos = dds::DATAREADER_QOS_DEFAULT;
  rqos.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
  rqos.durability().kind = dds::TRANSIENT_LOCAL_DURABILITY_QOS;
  rqos.history().kind = dds::KEEP_LAST_HISTORY_QOS;
  rqos.history().depth = 8;
  rqos.data_sharing().off();
  impl->writer = impl->publisher->create_datawriter(impl->topic, wqos);
  impl->reader = impl->subscriber->create_datareader(impl->topic, rqos);
  if (impl->writer == nullptr || impl->reader == nullptr) {
    return Error{Errc::kIo, "cannot create DDS writer or reader"};
  }
  return std::unique_ptr<HeartbeatLink>(new HeartbeatLink(std::move(impl)));
}

Status HeartbeatLink::Publish(UnixTime stamp, Duration uptime) {
  msgraphs::link::Heartbeat msg;
  msg.version(msgraphs::link::kHeartbeatVersion);
  msg.robot_id(impl_->self.value);
  msg.counter(impl_->next_sequence++);
  msg.stamp_unix_ns(static_cast<std::uint64_t>(stamp.nanoseconds_since_epoch()));
  msg.uptime_ns(static_cast<std::uint64_t>(uptime.nanoseconds()));
  msg.build(impl_->build_label);
  if (!impl_->writer->write(&msg)) return Error{Errc::kWouldBlock, "heartbeat write refused"};
  ++impl_->stats.sent;
  return Ok();
}

Expected<HeartbeatSample> HeartbeatLink::Receive(Duration timeout) {
  const SteadyTime deadline = platform::SteadyNow() + timeout;
  for (;;) {
    msgraphs::link::Heartbeat msg;
    dds::SampleInfo info;
    while (impl_->reader->take_next_sample(&msg, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      if (msg.version() != msgraphs::link::kHeartbeatVersion) {
        ++impl_->stats.rejected_version;
        continue;
      }
      if (msg.robot_id() == 0) {
        ++impl_->stats.rejected_invalid;
        continue;
      }
      if (msg.robot_id() == impl_->self.value) continue;  // our own writer, same topic
      ++impl_->stats.received;
      return HeartbeatSample{RobotId{msg.robot_id()}, msg.counter(),
                             UnixTime::FromNanoseconds(static_cast<std::int64_t>(msg.stamp_unix_ns())),
                             Duration::FromNanoseconds(static_cast<std::int64_t>(msg.uptime_ns())),
                             msg.build().to_string()};
    }
    const Duration left = deadline - platform::SteadyNow();
    if (left <= Duration()) return Error{Errc::kTimeout, "no heartbeat before the deadline"};
    impl_->reader->wait_for_unread_message(ToDds(left));
  }
}

int HeartbeatLink::matched_readers() const {
  dds::PublicationMatchedStatus status;
  impl_->writer->get_publication_matched_status(status);
  return status.current_count;
}

const HeartbeatStats& HeartbeatLink::stats() const { return impl_->stats; }

}  // namespace msgraphs::runtime::link
