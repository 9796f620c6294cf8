// SPDX-License-Identifier: MIT
#include "solver_worker.hpp"

#include <chrono>

namespace msgraphs::runtime {

void SolverWorker::Offer(core::SGraphSolveJob* job) {
  if (job == nullptr) return;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    offered_ = job;
  }
  wake_.notify_one();
}

void SolverWorker::Loop(const std::function<bool()>& stop) {
  while (!stop()) {
    core::SGraphSolveJob* job = nullptr;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      // A bounded wait: the node's stop flag is not this mutex's.
      wake_.wait_for(lock, std::chrono::milliseconds(50), [this] { return offered_ != nullptr; });
      job = offered_;
      offered_ = nullptr;
    }
    if (job != nullptr && job->TryClaim()) {
      job->Run();
      std::lock_guard<std::mutex> lock(mutex_);
      ++runs_;
    }
  }
}

std::uint64_t SolverWorker::runs() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return runs_;
}

}  // namespace msgraphs::runtime
