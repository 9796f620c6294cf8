// SPDX-License-Identifier: MIT
#include "msgraphs/platform/receive_metadata.hpp"

#include <cstring>

namespace msgraphs::platform {

ReceiveMetadata ParseReceiveMetadata(const msghdr& message) {
  ReceiveMetadata m;
  msghdr& h = const_cast<msghdr&>(message);  // the CMSG macros take non-const pointers
  for (cmsghdr* c = CMSG_FIRSTHDR(&h); c != nullptr; c = CMSG_NXTHDR(&h, c)) {
    if (c->cmsg_level != SOL_SOCKET) continue;
    if (c->cmsg_type == SO_TIMESTAMPNS) {
      timespec stamp{};
      std::memcpy(&stamp, CMSG_DATA(c), sizeof(stamp));
      m.has_time = true;
      m.time = UnixTime::FromNanoseconds(static_cast<std::int64_t>(stamp.tv_sec) * 1'000'000'000 + stamp.tv_nsec);
    } else if (c->cmsg_type == SO_RXQ_OVFL) {
      std::memcpy(&m.drop_count, CMSG_DATA(c), sizeof(m.drop_count));
      m.has_drop_count = true;
    }
  }
  return m;
}

}  // namespace msgraphs::platform
