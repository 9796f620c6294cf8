// SPDX-License-Identifier: MIT
#include "mission.hpp"

#include <cstdio>
#include <span>

#include "keyframe_baseline.hpp"

namespace msgraphs::tools::collab {

void Mission::Deliver() {
  for (std::size_t i = 0; i < radio.queue.size(); ++i) {  // Receive may queue answers
    const Radio::Message m = radio.queue[i];
    for (auto& to : robots) {
      if (to->index == m.from || (m.to != 0 && m.to != to->id())) continue;
      accounting.Add(static_cast<MessageType>(m.type), m.from, to->index, m.bytes.size());
      radio.sender = to->index;
      auto s = to->session.Receive(m.type, m.bytes, radio);
      if (!s && (s.error().code == Errc::kMalformed || s.error().code == Errc::kChecksum)) {
        if (++accounting.malformed <= 3)
          std::fprintf(stderr, "collab: robot %d rejected a message: %s\n", to->id(),
                       s.error().detail);
      }
    }
  }
  radio.queue.clear();
}

void Mission::Exchange(double now_s) {
  if (keyframes) {
    for (auto& r : robots) ExchangeKeyframes(*this, *r);
    for (auto& r : robots) MatchKeyframes(*this, *r);
    return;
  }
  for (auto& r : robots) {
    radio.sender = r->index;
    static_cast<void>(core::PublishNow(r->mapper, r->publisher, r->exchange, r->session, radio));
  }
  Deliver();
  // Match, deliver the cloud requests and their answers, and align what arrived.
  for (int round = 0; round < 2; ++round) {
    for (auto& r : robots) {
      radio.sender = r->index;
      r->session.Match(radio, now_s);
    }
    Deliver();
  }
  std::vector<core::MergeLogEntry> entries(64);
  for (auto& r : robots) {
    for (;;) {
      const std::uint64_t after = r->merge_log.empty() ? 0 : r->merge_log.back().sequence;
      const std::size_t n = r->session.MergeLog(after, entries);
      if (n == 0) break;
      r->merge_log.insert(r->merge_log.end(), entries.begin(), entries.begin() + static_cast<std::ptrdiff_t>(n));
    }
  }
  if (!feedback) return;
  for (auto& r : robots) {
    const std::size_t n = r->session.PlanePriors(priors);
    static_cast<void>(r->mapper.SetPlanePriors(std::span(priors.data(), n)));
  }
}

bool Mission::Merged(const Robot& a, int b_index) const {
  const auto robot = static_cast<std::uint16_t>(b_index + 1);
  return keyframes ? a.baseline.collab.has_robot(robot) : a.session.merged(robot);
}

Eigen::Isometry3d Mission::Origin(const Robot& a, int b_index) const {
  const auto robot = static_cast<std::uint16_t>(b_index + 1);
  return keyframes ? a.baseline.collab.T_self_robot(robot) : a.session.T_self_robot(robot);
}

std::vector<core::RoomMatch> Mission::Accepted(const Robot& a, int b_index) const {
  std::vector<core::RoomMatch> out;
  if (keyframes) {
    const auto list = a.baseline.matches.find(b_index);
    const auto keep = a.baseline.consistent.find(b_index);
    if (list == a.baseline.matches.end() || keep == a.baseline.consistent.end()) return out;
    for (std::uint32_t i : keep->second) out.push_back(list->second[i]);
  } else {
    out.resize(64);
    out.resize(a.session.ConsistentMatches(static_cast<std::uint16_t>(b_index + 1), out));
  }
  return out;
}

std::size_t Mission::Factors(const Robot& a, int b_index) const {
  const auto robot = static_cast<std::uint16_t>(b_index + 1);
  return keyframes ? a.baseline.collab.factors(robot)
                   : a.session.collaborative_graph().factors(robot);
}

}  // namespace msgraphs::tools::collab
