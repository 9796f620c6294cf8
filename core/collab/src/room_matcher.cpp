// SPDX-License-Identifier: MIT
#include "msgraphs/core/collab/room_matcher.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <numbers>

#include "msgraphs/core/geometry/se3.hpp"

namespace msgraphs::core {

Status RoomMatchConfig::Validate() const {
  if (!(sc_threshold > 0) || !(icp_fitness_threshold > 0) || !(vgicp_resolution_m > 0) ||
      !(consistency_translation_m > 0) || !(consistency_yaw_rad > 0) || min_consistent < 1 ||
      max_points < 100) {
    return Error{Errc::kInvalidConfig, "room matching: thresholds must be positive"};
  }
  return vgicp.Validate();
}

Status RoomMatcher::Init(const RoomMatchConfig& config) {
  if (auto s = config.Validate(); !s) return s;
  config_ = config;
  tree_a_.Init(config.max_points);
  tree_b_.Init(config.max_points);
  normals_.Init(config.max_points);
  covariances_a_.Init(config.max_points);
  covariances_b_.Init(config.max_points);
  map_a_.Init(config.max_points);
  vgicp_.Init(config.max_points);
  return Ok();
}

Eigen::Isometry3d MatchFromRoomFrames(const Eigen::Isometry3d& T_mapa_rooma,
                                      const Eigen::Isometry3d& T_mapb_roomb,
                                      double yaw_rad) {
  Eigen::Isometry3d T_rooma_roomb = Eigen::Isometry3d::Identity();
  T_rooma_roomb.linear() = RotZ(yaw_rad);
  return T_mapa_rooma * T_rooma_roomb * T_mapb_roomb.inverse();
}

Status RoomMatcher::FineAlign(std::span<const Eigen::Vector3f> cloud_a,
                              const Eigen::Isometry3d& T_mapa_rooma,
                              std::span<const Eigen::Vector3f> cloud_b,
                              const Eigen::Isometry3d& T_mapb_roomb,
                              double yaw_rad,
                              RoomMatch& match) {
  if (cloud_a.size() > config_.max_points || cloud_b.size() > config_.max_points) {
    return Error{Errc::kCapacityExceeded, "room matching: room cloud larger than max_points"};
  }
  if (auto s = tree_a_.Build(cloud_a); !s) return s;
  if (auto s = tree_b_.Build(cloud_b); !s) return s;
  if (auto s = EstimateCovariances(cloud_a, tree_a_, {}, normals_, covariances_a_); !s)
    return s.error();
  if (auto s = EstimateCovariances(cloud_b, tree_b_, {}, normals_, covariances_b_); !s)
    return s.error();
  if (auto s = map_a_.Build(cloud_a, covariances_a_.span(), config_.vgicp_resolution_m); !s)
    return s;
  bool found = false;
  double best = config_.icp_fitness_threshold;
  // The Scan Context yaw first, then its quarter turns (a rectangle looks alike under them).
  for (int quarter = 0; quarter < 4; ++quarter) {
    Eigen::Isometry3d guess = Eigen::Isometry3d::Identity();
    guess.linear() = RotZ(yaw_rad + quarter * std::numbers::pi / 2);
    auto result = vgicp_.Align(cloud_b, covariances_b_.span(), map_a_, cloud_a, tree_a_, guess,
                               config_.vgicp);
    if (!result || !result->converged || !(result->fitness < best)) continue;
    best = result->fitness;
    match.fitness_m2 = result->fitness;
    match.T_a_b = T_mapa_rooma * result->T_target_source * T_mapb_roomb.inverse();
    match.fine_aligned = true;
    found = true;
    if (quarter == 0 && best < 0.5 * config_.icp_fitness_threshold)
      break;  // clearly right: spare the others
  }
  if (!found) return Error{Errc::kNotConverged, "room matching: no seed aligned within ICP_th"};
  return Ok();
}

namespace {

// Maximum clique of the agreement graph restricted to `allowed`, by Bron-Kerbosch with pivoting
// over bit sets (n <= 64, sparse in practice).
std::uint64_t MaximumClique(const std::uint64_t* adjacency, std::uint64_t allowed) {
  std::uint64_t best = 0;
  struct Frame {
    std::uint64_t r, p, x;
  };
  Frame stack[64 * 2 + 2];
  std::size_t top = 0;
  stack[top++] = {0, allowed, 0};
  while (top > 0) {
    Frame f = stack[--top];
    if (f.p == 0 && f.x == 0) {
      if (std::popcount(f.r) > std::popcount(best)) best = f.r;
      continue;
    }
    if (std::popcount(f.r) + std::popcount(f.p) <= std::popcount(best)) continue;  // cannot beat it
    const std::uint64_t px = f.p | f.x;
    const int pivot = std::countr_zero(px);
    std::uint64_t candidates = f.p & ~adjacency[pivot];
    while (candidates != 0 && top + 2 < sizeof(stack) / sizeof(stack[0])) {
      const int v = std::countr_zero(candidates);
      const std::uint64_t bit = 1ull << v;
      candidates &= ~bit;
      stack[top++] = {f.r | bit, f.p & adjacency[v], f.x & adjacency[v]};
      f.p &= ~bit;
      f.x |= bit;
    }
  }
  return best;
}

}  // namespace

std::size_t MatchHypotheses(std::span<const RoomMatch> matches,
                            const RoomMatchConfig& config,
                            std::size_t min_matches,
                            std::span<std::uint64_t> out) {
  const std::size_t n = std::min<std::size_t>(matches.size(), 64);
  std::uint64_t adjacency[64] = {};
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) {
      const Eigen::Isometry3d D = matches[i].T_a_b.inverse() * matches[j].T_a_b;
      const double yaw = std::fabs(std::atan2(D.linear()(1, 0), D.linear()(0, 0)));
      if (D.translation().head<2>().norm() < config.consistency_translation_m &&
          yaw < config.consistency_yaw_rad) {
        adjacency[i] |= 1ull << j;
        adjacency[j] |= 1ull << i;
      }
    }
  }
  std::uint64_t left = n == 64 ? ~0ull : ((1ull << n) - 1);
  std::size_t count = 0;
  while (count < out.size() && left != 0) {
    const std::uint64_t clique = MaximumClique(adjacency, left);
    if (static_cast<std::size_t>(std::popcount(clique)) < std::max<std::size_t>(min_matches, 1))
      break;
    out[count++] = clique;
    left &= ~clique;
  }
  return count;
}

std::size_t ConsistentMatches(std::span<const RoomMatch> matches,
                              const RoomMatchConfig& config,
                              std::span<std::uint32_t> out) {
  std::uint64_t hypotheses[2] = {};
  const std::size_t found = MatchHypotheses(matches, config, config.min_consistent, hypotheses);
  if (found == 0) return 0;
  // A tie is no answer: in a symmetric building two hypotheses can each gather the same
  // number of agreeing matches, and taking the first found merges the maps metres apart.
  // Wait until one of them has more (a match elsewhere breaks the symmetry), or let the caller
  // tell them apart by the rest of the maps (MatchHypotheses, WallAgreement_m).
  if (found == 2 && std::popcount(hypotheses[1]) == std::popcount(hypotheses[0])) return 0;
  return HypothesisMembers(hypotheses[0], out);
}

std::size_t HypothesisMembers(std::uint64_t hypothesis, std::span<std::uint32_t> out) {
  std::size_t count = 0;
  for (std::uint32_t i = 0; i < 64 && count < out.size(); ++i) {
    if ((hypothesis >> i) & 1ull) out[count++] = i;
  }
  return count;
}

}  // namespace msgraphs::core
