// SPDX-License-Identifier: MIT
#include "msgraphs/base/expected.hpp"

namespace msgraphs {

const char* ToString(Errc code) noexcept {
  switch (code) {
    case Errc::kInvalidArgument: return "invalid argument";
    case Errc::kMalformed: return "malformed";
    case Errc::kChecksum: return "checksum mismatch";
    case Errc::kCapacityExceeded: return "capacity exceeded";
    case Errc::kWouldBlock: return "would block";
    case Errc::kTimeout: return "timeout";
    case Errc::kNotConverged: return "not converged";
    case Errc::kDegenerate: return "degenerate input";
    case Errc::kOutOfOrder: return "out of order";
    case Errc::kNotFound: return "not found";
    case Errc::kUnsupported: return "unsupported";
    case Errc::kPermissionDenied: return "permission denied";
    case Errc::kIo: return "I/O error";
    case Errc::kInvalidConfig: return "invalid configuration";
  }
  return "unknown error";
}

}  // namespace msgraphs
