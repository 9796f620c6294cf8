// SPDX-License-Identifier: MIT
#include "msgraphs/drivers/velodyne/velodyne_source.hpp"

#include "msgraphs/platform/clock.hpp"

namespace msgraphs::drivers::velodyne {

Expected<VelodyneSource> VelodyneSource::Open(const VelodyneSourceConfig& config) {
  auto decoder = DataPacketDecoder::Create(config.decoder);
  if (!decoder) return decoder.error();
  auto assembler = ScanAssembler::Create(config.scan);
  if (!assembler) return assembler.error();
  platform::UdpReceiverConfig udp;
  udp.bind = {config.bind_address, config.data_port};
  udp.expected_source = config.sensor_address;
  udp.expected_payload_bytes = kDataPacketBytes;
  udp.receive_buffer_bytes = config.receive_buffer_bytes;
  auto data = platform::UdpReceiver::Open(udp);
  if (!data) return data.error();
  udp.bind.port = config.position_port;
  udp.expected_payload_bytes = kPositionPacketBytes;
  udp.receive_buffer_bytes = 256 << 10;  // 125 packets/s of 512 bytes
  udp.batch = 16;
  auto position = platform::UdpReceiver::Open(udp);
  if (!position) return position.error();
  return VelodyneSource(config, std::move(decoder).value(), std::move(assembler).value(),
                        std::move(data).value(), std::move(position).value());
}

VelodyneSource::VelodyneSource(const VelodyneSourceConfig& config, DataPacketDecoder decoder,
                               ScanAssembler assembler, platform::UdpReceiver data,
                               platform::UdpReceiver position)
    : config_(config),
      decoder_(std::move(decoder)),
      assembler_(std::move(assembler)),
      data_(std::move(data)),
      position_socket_(std::move(position)),
      points_(kMaxPointsPerPacket) {}

VelodyneSourceStats VelodyneSource::stats() const {
  VelodyneSourceStats s = stats_;
  s.data_udp = data_.stats();
  s.position_udp = position_socket_.stats();
  s.clock_resets = clock_.resets();
  return s;
}

bool VelodyneSource::ProcessData(const platform::ReceivedDatagram& datagram) {
  auto decoded = decoder_.Decode(datagram.payload, points_);
  if (!decoded) {
    ++stats_.malformed_data;
    stats_.last_error = decoded.error().detail;
    return false;
  }
  ++stats_.data_packets;
  stats_.points += decoded->points;
  stats_.no_return += decoded->no_return;
  stats_.out_of_range += decoded->out_of_range;
  const UnixTime first_firing =
      config_.use_device_time
          ? clock_.Map(datagram.kernel_time, decoded->device_time_us, decoded->packet_duration_ns)
          : datagram.kernel_time - Duration::FromNanoseconds(decoded->packet_duration_ns);
  return assembler_.AddPacket(first_firing, *decoded, std::span(points_).first(decoded->points));
}

void VelodyneSource::ProcessPositions() {
  auto n = position_socket_.Receive(SteadyTime());  // never waits
  if (!n) return;
  for (std::size_t i = 0; i < *n; ++i) {
    auto p = DecodePositionPacket(position_socket_.datagram(i).payload);
    if (!p) {
      ++stats_.malformed_position;
      stats_.last_error = p.error().detail;
      continue;
    }
    ++stats_.position_packets;
    position_ = *p;
  }
}

Expected<bool> VelodyneSource::Poll(SteadyTime deadline) {
  for (;;) {
    while (batch_next_ < batch_size_) {
      if (ProcessData(data_.datagram(batch_next_++))) return true;
    }
    const int fds[2] = {data_.fd(), position_socket_.fd()};
    auto ready = platform::WaitReadable(fds, deadline);
    if (!ready) return ready.error();
    if ((*ready & 2u) != 0) ProcessPositions();
    if ((*ready & 1u) != 0) {
      auto n = data_.Receive(SteadyTime());
      if (!n) return n.error();
      batch_size_ = *n;
      batch_next_ = 0;
    } else if (*ready == 0) {
      return false;  // deadline
    }
    if (batch_size_ == batch_next_ && platform::SteadyNow() >= deadline) return false;
  }
}

}  // namespace msgraphs::drivers::velodyne
