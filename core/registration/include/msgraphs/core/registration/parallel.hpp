// SPDX-License-Identifier: MIT
// Core has no threads of its own. Work that can run in parallel takes an optional executor from
// the caller (the runtime owns the threads, with their priorities and cores); without one it
// runs serially.
#pragma once

#include <cstddef>

namespace msgraphs::core {

class ParallelExecutor {
 public:
  virtual ~ParallelExecutor() = default;
  /// Runs fn(context, chunk) for chunk in [0, chunks), in any order and on any threads, and
  /// returns when all have finished.
  virtual void Run(std::size_t chunks, void (*fn)(void* context, std::size_t chunk), void* context) const = 0;
  /// How many chunks are worth making (about the number of threads).
  virtual std::size_t concurrency() const = 0;
};

}  // namespace msgraphs::core
