// SPDX-License-Identifier: MIT
#include "msgraphs/drivers/can_odometry/socketcan.hpp"

#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <vector>

#include "msgraphs/drivers/can_odometry/odometry_frames.hpp"
#include "msgraphs/platform/clock.hpp"
#include "msgraphs/platform/receive_metadata.hpp"
#include "msgraphs/platform/udp_socket.hpp"

namespace msgraphs::drivers::can_odometry {
namespace {

Expected<int> OpenBound(std::string_view interface) {
  if (interface.empty() || interface.size() >= IFNAMSIZ) {
    return Error{Errc::kInvalidConfig, "socketcan: bad interface name"};
  }
  const int fd = ::socket(PF_CAN, SOCK_RAW | SOCK_CLOEXEC, CAN_RAW);
  if (fd < 0) {
    if (errno == EAFNOSUPPORT || errno == EPROTONOSUPPORT) {
      return Error{Errc::kUnsupported, "socketcan: this kernel has no SocketCAN (AF_CAN)", errno};
    }
    return Error{Errc::kIo, "socketcan: socket() failed", errno};
  }
  char name[IFNAMSIZ] = {};
  std::memcpy(name, interface.data(), interface.size());
  const unsigned index = ::if_nametoindex(name);
  if (index == 0) {
    ::close(fd);
    return Error{Errc::kNotFound, "socketcan: no such CAN interface", errno};
  }
  sockaddr_can address{};
  address.can_family = AF_CAN;
  address.can_ifindex = static_cast<int>(index);
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&address), sizeof(address)) != 0) {
    const int e = errno;
    ::close(fd);
    return Error{Errc::kIo, "socketcan: bind failed", e};
  }
  return fd;
}

}  // namespace

SocketCanConfig SocketCanConfig::Odometry(std::string_view interface) {
  SocketCanConfig c;
  c.interface = {};
  for (std::size_t i = 0; i < interface.size() && i + 1 < kMaxInterfaceName; ++i) {
    c.interface[i] = interface[i];
  }
  c.filter_ids.push_back(kPlanarId);
  c.filter_ids.push_back(kSpatialId);
  c.filter_ids.push_back(kSampleTimeId);
  return c;
}

Status SocketCanConfig::Validate() const {
  if (interface[0] == '\0') return Error{Errc::kInvalidConfig, "socketcan: empty interface name"};
  if (batch == 0 || batch > 256) return Error{Errc::kInvalidConfig, "socketcan: batch must be 1..256"};
  for (std::uint32_t id : filter_ids) {
    if (id > CAN_SFF_MASK) return Error{Errc::kInvalidConfig, "socketcan: filter ids are 11-bit"};
  }
  return Ok();
}

struct SocketCanSource::Buffers {
  std::vector<can_frame> frames;
  std::vector<std::uint8_t> control;
  std::vector<mmsghdr> headers;
  std::vector<iovec> iov;
  std::vector<TimedCanFrame> ready;
};

Expected<SocketCanSource> SocketCanSource::Open(const SocketCanConfig& config) {
  if (Status s = config.Validate(); !s) return s.error();
  auto fd = OpenBound(config.interface.data());
  if (!fd) return fd.error();
  SocketCanSource source(*fd, config.batch);
  if (!config.filter_ids.empty()) {
    can_filter filters[16];
    std::size_t n = 0;
    for (std::uint32_t id : config.filter_ids) {
      // Exact standard-id match: compare all 11 id bits and the EFF and RTR flags.
      filters[n++] = can_filter{id, CAN_SFF_MASK | CAN_EFF_FLAG | CAN_RTR_FLAG};
    }
    if (::setsockopt(*fd, SOL_CAN_RAW, CAN_RAW_FILTER, filters,
                     static_cast<socklen_t>(n * sizeof(can_filter))) != 0) {
      return Error{Errc::kIo, "socketcan: CAN_RAW_FILTER failed", errno};
    }
  }
  if (config.receive_error_frames) {
    const can_err_mask_t mask = CAN_ERR_MASK;
    if (::setsockopt(*fd, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &mask, sizeof(mask)) != 0) {
      return Error{Errc::kIo, "socketcan: CAN_RAW_ERR_FILTER failed", errno};
    }
  }
  const int one = 1;
  if (config.receive_buffer_bytes > 0) {
    const int want = config.receive_buffer_bytes;
    if (::setsockopt(*fd, SOL_SOCKET, SO_RCVBUFFORCE, &want, sizeof(want)) != 0) {
      static_cast<void>(::setsockopt(*fd, SOL_SOCKET, SO_RCVBUF, &want, sizeof(want)));
    }
  }
  if (::setsockopt(*fd, SOL_SOCKET, SO_TIMESTAMPNS, &one, sizeof(one)) != 0 ||
      ::setsockopt(*fd, SOL_SOCKET, SO_RXQ_OVFL, &one, sizeof(one)) != 0) {
    return Error{Errc::kIo, "socketcan: timestamp/overflow options failed", errno};
  }
  return source;
}

SocketCanSource::SocketCanSource(int fd, std::size_t batch)
    : fd_(fd), batch_(batch), buffers_(std::make_unique<Buffers>()) {
  buffers_->frames.resize(batch);
  buffers_->control.resize(batch * platform::kReceiveControlBytes);
  buffers_->headers.resize(batch);
  buffers_->iov.resize(batch);
  buffers_->ready.resize(batch);
}

SocketCanSource::SocketCanSource(SocketCanSource&& other) noexcept
    : fd_(other.fd_),
      batch_(other.batch_),
      buffers_(std::move(other.buffers_)),
      ready_(other.ready_),
      last_overflow_(other.last_overflow_),
      stats_(other.stats_) {
  other.fd_ = -1;
}

SocketCanSource::~SocketCanSource() {
  if (fd_ >= 0) ::close(fd_);
}

const TimedCanFrame& SocketCanSource::frame(std::size_t i) const {
  MSGRAPHS_ASSERT(i < ready_, "SocketCanSource::frame index beyond the batch");
  return buffers_->ready[i];
}

Expected<std::size_t> SocketCanSource::Receive(SteadyTime deadline) {
  ready_ = 0;
  Buffers& b = *buffers_;
  for (;;) {
    for (std::size_t i = 0; i < batch_; ++i) {
      b.iov[i] = {&b.frames[i], sizeof(can_frame)};
      msghdr& h = b.headers[i].msg_hdr;
      h = msghdr{};
      h.msg_iov = &b.iov[i];
      h.msg_iovlen = 1;
      h.msg_control = b.control.data() + i * platform::kReceiveControlBytes;
      h.msg_controllen = platform::kReceiveControlBytes;
    }
    const int n = ::recvmmsg(fd_, b.headers.data(), static_cast<unsigned>(batch_), MSG_DONTWAIT, nullptr);
    if (n < 0) {
      if (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) {
        return Error{Errc::kIo, "socketcan: recvmmsg failed", errno};
      }
      if (platform::SteadyNow() >= deadline) return std::size_t{0};
      const int fds[1] = {fd_};
      auto ready = platform::WaitReadable(fds, deadline);
      if (!ready) return ready.error();
      if (*ready == 0) return std::size_t{0};
      continue;
    }
    for (int i = 0; i < n; ++i) {
      const auto k = static_cast<std::size_t>(i);
      const platform::ReceiveMetadata meta = platform::ParseReceiveMetadata(b.headers[k].msg_hdr);
      platform::AccumulateDrops(meta, last_overflow_, stats_.kernel_drops);
      if (b.headers[k].msg_len != sizeof(can_frame)) {
        ++stats_.fd_frames;
        continue;
      }
      const can_frame& raw = b.frames[k];
      if ((raw.can_id & CAN_ERR_FLAG) != 0) {
        ++stats_.error_frames;
        if ((raw.can_id & CAN_ERR_BUSOFF) != 0) ++stats_.bus_off;
        continue;
      }
      TimedCanFrame& out = b.ready[ready_++];
      out.kernel_time = meta.has_time ? meta.time : platform::UnixNow();
      out.frame = CanFrame{};
      out.frame.extended = (raw.can_id & CAN_EFF_FLAG) != 0;
      out.frame.remote = (raw.can_id & CAN_RTR_FLAG) != 0;
      out.frame.id = raw.can_id & (out.frame.extended ? CAN_EFF_MASK : CAN_SFF_MASK);
      out.frame.length = raw.len > 8 ? 8 : raw.len;
      std::memcpy(out.frame.data.data(), raw.data, out.frame.length);
      ++stats_.frames;
    }
    if (ready_ > 0) return ready_;
  }
}

Expected<SocketCanSender> SocketCanSender::Open(std::string_view interface) {
  auto fd = OpenBound(interface);
  if (!fd) return fd.error();
  // A sender does not read: drop everything the socket would otherwise queue.
  static_cast<void>(::setsockopt(*fd, SOL_CAN_RAW, CAN_RAW_FILTER, nullptr, 0));
  return SocketCanSender(*fd);
}

SocketCanSender::SocketCanSender(SocketCanSender&& other) noexcept : fd_(other.fd_) { other.fd_ = -1; }

SocketCanSender::~SocketCanSender() {
  if (fd_ >= 0) ::close(fd_);
}

Status SocketCanSender::Send(const CanFrame& frame) {
  if (frame.length > 8) return Error{Errc::kInvalidArgument, "socketcan: classic frames carry 0..8 bytes"};
  can_frame raw{};
  raw.can_id = frame.id | (frame.extended ? CAN_EFF_FLAG : 0u) | (frame.remote ? CAN_RTR_FLAG : 0u);
  raw.len = frame.length;
  std::memcpy(raw.data, frame.data.data(), frame.length);
  for (;;) {
    const ssize_t n = ::write(fd_, &raw, sizeof(raw));
    if (n == static_cast<ssize_t>(sizeof(raw))) return Ok();
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && errno == ENOBUFS) {  // the interface queue is full: wait for room
      pollfd p{fd_, POLLOUT, 0};
      static_cast<void>(::poll(&p, 1, 100));
      continue;
    }
    return Error{Errc::kIo, "socketcan: write failed", n < 0 ? errno : EIO};
  }
}

}  // namespace msgraphs::drivers::can_odometry
