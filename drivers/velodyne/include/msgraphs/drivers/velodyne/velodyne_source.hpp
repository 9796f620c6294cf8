// SPDX-License-Identifier: MIT
// A live VLP-16 on UDP: the data and position sockets, decoding, device-time mapping and scan
// assembly, with counters for everything that does not become a point. This is what the
// runtime's LiDAR thread polls. All buffers are allocated at Open.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "msgraphs/base/clock_offset_filter.hpp"
#include "msgraphs/base/expected.hpp"
#include "msgraphs/base/ipv4.hpp"
#include "msgraphs/drivers/velodyne/data_packet_decoder.hpp"
#include "msgraphs/drivers/velodyne/device_clock.hpp"
#include "msgraphs/drivers/velodyne/position_packet.hpp"
#include "msgraphs/drivers/velodyne/scan_assembler.hpp"
#include "msgraphs/platform/udp_socket.hpp"

namespace msgraphs::drivers::velodyne {

struct VelodyneSourceConfig {
  std::uint32_t bind_address = kIpv4Any;
  std::uint16_t data_port = kDefaultDataPort;
  std::uint16_t position_port = kDefaultPositionPort;
  /// Accept packets only from the sensor (0 = any sender), e.g. 192.168.1.201.
  std::uint32_t sensor_address = 0;
  int receive_buffer_bytes = 8 << 20;
  DecoderConfig decoder;
  ScanAssemblerConfig scan;
  /// Time points by the sensor's clock mapped to the host (true), or by arrival time minus the
  /// packet's duration (false: for sensors whose clock is known to be broken).
  bool use_device_time = true;
};

struct VelodyneSourceStats {
  platform::UdpReceiverStats data_udp;
  platform::UdpReceiverStats position_udp;
  std::uint64_t data_packets = 0;        ///< decoded
  std::uint64_t malformed_data = 0;      ///< right size, wrong content: counted, skipped
  std::uint64_t position_packets = 0;
  std::uint64_t malformed_position = 0;
  std::uint64_t points = 0;
  std::uint64_t no_return = 0;
  std::uint64_t out_of_range = 0;
  std::uint64_t clock_resets = 0;
  const char* last_error = "";  ///< reason of the latest malformed packet
};

class VelodyneSource {
 public:
  static Expected<VelodyneSource> Open(const VelodyneSourceConfig& config);

  /// Processes traffic until a scan completes (true: it is in scan()) or `deadline` passes
  /// (false). Datagrams after a completed scan stay queued for the next call.
  Expected<bool> Poll(SteadyTime deadline);

  const Scan& scan() const { return assembler_.completed(); }
  /// The latest position packet, if any arrived.
  const std::optional<PositionPacket>& position() const { return position_; }
  VelodyneSourceStats stats() const;
  const ScanAssemblerStats& scan_stats() const { return assembler_.stats(); }
  std::uint16_t data_port() const { return data_.bound_port(); }
  std::uint16_t position_port() const { return position_socket_.bound_port(); }

 private:
  VelodyneSource(const VelodyneSourceConfig& config, DataPacketDecoder decoder, ScanAssembler assembler,
                 platform::UdpReceiver data, platform::UdpReceiver position);
  bool ProcessData(const platform::ReceivedDatagram& datagram);
  void ProcessPositions();

  VelodyneSourceConfig config_;
  DataPacketDecoder decoder_;
  ScanAssembler assembler_;
  platform::UdpReceiver data_;
  platform::UdpReceiver position_socket_;
  DeviceClockSync clock_;
  std::vector<VelodynePoint> points_;
  std::size_t batch_size_ = 0;   // datagrams in the current data batch
  std::size_t batch_next_ = 0;   // the next one to process
  std::optional<PositionPacket> position_;
  VelodyneSourceStats stats_;
};

}  // namespace msgraphs::drivers::velodyne
