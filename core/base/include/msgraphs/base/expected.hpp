// SPDX-License-Identifier: MIT
// Expected<T>: the result type for failures that are part of normal operation (a malformed
// packet, a full queue, a solver that did not converge). Contract violations (bugs) go through
// MSGRAPHS_ASSERT instead; see assert.hpp and docs/conventions.md.
#pragma once

#include <cstdint>
#include <type_traits>
#include <utility>
#include <variant>

#include "msgraphs/base/assert.hpp"

namespace msgraphs {

/// Error codes. Stable: they are counted, logged and compared in tests.
enum class Errc : std::uint8_t {
  kInvalidArgument,    ///< caller passed a value outside the documented domain
  kMalformed,          ///< input bytes or text do not follow their format
  kChecksum,           ///< a CRC or checksum did not match
  kCapacityExceeded,   ///< a bounded store is full; the documented overflow policy applied
  kWouldBlock,         ///< non-blocking call has nothing to do now
  kTimeout,            ///< a deadline passed
  kNotConverged,       ///< an iterative algorithm stopped without meeting its criteria
  kDegenerate,         ///< input is valid but carries too little information (empty, collinear)
  kOutOfOrder,         ///< a timestamp or sequence number went backwards or repeated
  kNotFound,           ///< a looked-up item does not exist
  kUnsupported,        ///< a valid request this build or device cannot serve
  kPermissionDenied,   ///< the OS refused (e.g. real-time priority without CAP_SYS_NICE)
  kIo,                 ///< an OS call failed; Error::sys_errno says why
  kInvalidConfig,      ///< configuration failed validation
};

/// Human-readable name of a code, e.g. "malformed". Static storage; never allocates.
const char* ToString(Errc code) noexcept;

/// An error value: a code, a static explanation and, for OS failures, errno.
/// `detail` must point to static storage (a string literal): errors are copied around freely
/// and never own memory, so building one never allocates.
struct Error {
  Errc code;
  const char* detail = "";
  int sys_errno = 0;
};

/// Holds either a T or an Error. No heap, no exceptions: accessing the wrong side is a
/// contract violation (MSGRAPHS_ASSERT), not UB and not a throw.
template <typename T>
class [[nodiscard]] Expected {
  static_assert(!std::is_reference_v<T>, "Expected<T&> is not supported");
  static_assert(!std::is_same_v<std::remove_cv_t<T>, Error>, "Expected<Error> is ambiguous");

 public:
  Expected(const T& value) : storage_(std::in_place_index<0>, value) {}  // NOLINT: implicit by design
  Expected(T&& value) : storage_(std::in_place_index<0>, std::move(value)) {}  // NOLINT
  Expected(Error error) : storage_(std::in_place_index<1>, error) {}  // NOLINT

  bool has_value() const noexcept { return storage_.index() == 0; }
  explicit operator bool() const noexcept { return has_value(); }

  T& value() & {
    MSGRAPHS_ASSERT(has_value(), "Expected::value() on an error");
    return *std::get_if<0>(&storage_);
  }
  const T& value() const& {
    MSGRAPHS_ASSERT(has_value(), "Expected::value() on an error");
    return *std::get_if<0>(&storage_);
  }
  T&& value() && {
    MSGRAPHS_ASSERT(has_value(), "Expected::value() on an error");
    return std::move(*std::get_if<0>(&storage_));
  }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }

  const Error& error() const {
    MSGRAPHS_ASSERT(!has_value(), "Expected::error() on a value");
    return *std::get_if<1>(&storage_);
  }

  template <typename U>
  T value_or(U&& fallback) const& {
    return has_value() ? *std::get_if<0>(&storage_) : static_cast<T>(std::forward<U>(fallback));
  }

 private:
  std::variant<T, Error> storage_;
};

/// Success or an Error, for operations without a result value.
template <>
class [[nodiscard]] Expected<void> {
 public:
  Expected() = default;
  Expected(Error error) : error_(error), ok_(false) {}  // NOLINT: implicit by design

  bool has_value() const noexcept { return ok_; }
  explicit operator bool() const noexcept { return ok_; }
  const Error& error() const {
    MSGRAPHS_ASSERT(!ok_, "Expected::error() on success");
    return error_;
  }

 private:
  Error error_{Errc::kInvalidArgument};
  bool ok_ = true;
};

using Status = Expected<void>;

/// `return Ok();` from a function returning Status.
inline Status Ok() { return {}; }

}  // namespace msgraphs
