// SPDX-License-Identifier: MIT
#include "msgraphs/tools/solver_thread.hpp"

namespace msgraphs::tools {

void SolverThread::Follow(core::LocalMapper& mapper) {
  if (mapper.stats().full_solves_begun == solves_begun_) return;
  solves_begun_ = mapper.stats().full_solves_begun;
  core::SGraphSolveJob* job = mapper.background_solve();
  if (job == nullptr) return;
  // The previous job was applied before this one began, but its thread may not have started
  // (the mapper then ran that job itself) and may claim this one: the new thread then finds it
  // claimed. Either way one thread runs it.
  Join();
  thread_ = std::jthread([job] {
    if (job->TryClaim()) job->Run();
  });
}

void SolverThread::Join() {
  if (thread_.joinable()) thread_.join();
}

}  // namespace msgraphs::tools
