// SPDX-License-Identifier: MIT
// The collaborative graph's state (collaborative_graph.hpp), shared by its node and link
// halves: origins, wall and room nodes, the links between them, and the update's bookkeeping.
#pragma once

#include <ceres/ceres.h>

#include <cmath>
#include <memory>
#include <vector>

#include "collaborative_graph_factors.hpp"
#include "msgraphs/core/graph/collaborative_graph.hpp"
#include "s_graph_factors.hpp"

namespace msgraphs::core {

struct CollaborativeGraph::Impl {
  using Gravity = collab_factors::Gravity;
  CollaborativeGraphConfig config;
  std::uint16_t self = 0;
  std::unique_ptr<ceres::Problem> problem;
  std::unique_ptr<ceres::LossFunction> huber;
  ceres::EigenQuaternionManifold quaternion_manifold;
  ceres::SphereManifold<3> sphere_manifold;
  struct Origin {
    double q[4] = {0, 0, 0, 1};
    double t[3] = {0, 0, 0};
    bool known = false;     // has an estimate
    bool declared = false;  // SetInitial since BeginUpdate (self always)
    bool in_problem = false;
    bool moved = false;  // SetInitial moved it this update: its nodes restart from their measurements
    std::size_t factors = 0;
    std::uint32_t origin_ordinal = 0, floor_ordinal = 0;  // declarations this update
  };
  struct Wall {
    bool used = false, declared = false;
    std::uint16_t robot = 0;
    DistilledWall measured;  // in its robot's frame
    double n[3] = {1, 0, 0};
    double d = 0;
    sgraph::PlaneResidual* functor = nullptr;  // owned by the problem; updated in place
  };
  struct Room {
    bool used = false, declared = false;
    std::uint16_t robot = 0;
    std::uint32_t id = 0;
    double yaw_rad = 0;
    bool corridor = false;
    double p[3] = {0, 0, 0};
    collab_factors::RoomMeasured* functor = nullptr;
  };
  // Factors between nodes, and an origin's own measurements; a node's measurement belongs to
  // the node. Keyed by kind and (a, b): two node slots, or a robot and the ordinal of the
  // declaration in this update.
  // A corridor pair's factor turns with the corridor's robot: A's (kCorridorA) or B's.
  enum class Kind : std::uint8_t { kWallSame, kRoomSame, kCorridorA, kCorridorB, kRoomYaw, kOrigin, kFloor, kRoomWalls };
  struct Link {
    bool used = false, declared = false;
    Kind kind = Kind::kWallSame;
    std::uint32_t a = 0, b = 0, c = 0;  // c: a room-to-wall edge's second wall
    ceres::ResidualBlockId block = nullptr;
    void* functor = nullptr;  // the Kind's functor, owned by the problem
  };
  // Slots: twice the capacities, so that an update's new elements fit beside the old ones the
  // sweep will drop; node addresses never move once Ceres holds them.
  std::vector<Origin> origins;
  std::vector<Wall> walls;
  std::vector<Room> rooms;
  std::vector<Link> links;
  std::size_t declared_walls = 0, declared_rooms = 0, declared_factors = 0;
  CollaborativeGraphUpdate update;
  std::vector<double> backup;  // solve snapshot

  void Reset() {
    ceres::Problem::Options options;
    options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    options.enable_fast_removal = true;  // the sweep removes what an update left out
    problem = std::make_unique<ceres::Problem>(options);
    for (Origin& o : origins) o.in_problem = false;
    for (Wall& w : walls) w = Wall{};
    for (Room& r : rooms) r = Room{};
    for (Link& l : links) l = Link{};
  }
  Origin* Get(std::uint16_t robot) {
    if (robot >= origins.size() || !origins[robot].known || !origins[robot].declared) return nullptr;
    return &origins[robot];
  }
  // Adds the origin's blocks on first use (self's held constant; the others get gravity).
  void Use(std::uint16_t robot) {
    Origin& o = origins[robot];
    if (o.in_problem) return;
    o.in_problem = true;
    problem->AddParameterBlock(o.q, 4, &quaternion_manifold);
    problem->AddParameterBlock(o.t, 3);
    if (robot == self) {
      problem->SetParameterBlockConstant(o.q);
      problem->SetParameterBlockConstant(o.t);
      return;
    }
    problem->AddResidualBlock(
        new ceres::AutoDiffCostFunction<Gravity, 2, 4>(new Gravity{1.0 / config.gravity_sigma_rad}),
        nullptr, o.q);
  }
  Eigen::Isometry3d Pose(std::uint16_t robot) const {
    const Origin& o = origins[robot];
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::Quaterniond(o.q[3], o.q[0], o.q[1], o.q[2]).normalized().toRotationMatrix();
    T.translation() << o.t[0], o.t[1], o.t[2];
    return T;
  }
  Status HasRoomForFactors(std::size_t n) const {
    if (declared_factors + n > config.max_factors)
      return Error{Errc::kCapacityExceeded, "collaborative graph: factor store full"};
    return Ok();
  }
  Link* FindLink(Kind kind, std::uint32_t a, std::uint32_t b, std::uint32_t c = 0) {
    for (Link& l : links) {
      if (l.used && l.kind == kind && l.a == a && l.b == b && l.c == c) return &l;
    }
    return nullptr;
  }
  // A link declared in this update: the existing one (its functor updated by `update_functor`)
  // or a new one from `add` (returns its residual block and functor).
  template <typename Functor, typename Add>
  void DeclareLink(Kind kind, std::uint32_t a, std::uint32_t b, const Functor& value, Add add,
                   std::uint32_t c = 0) {
    Link* l = FindLink(kind, a, b, c);
    if (l != nullptr) {
      *static_cast<Functor*>(l->functor) = value;
      if (!l->declared) ++update.kept;
    } else {
      for (Link& free : links) {
        if (free.used) continue;
        l = &free;
        break;
      }
      // Slots are twice the capacity and at most max_factors are declared: one is free.
      auto* functor = new Functor(value);
      l->used = true;
      l->kind = kind;
      l->a = a;
      l->b = b;
      l->c = c;
      l->functor = functor;
      l->block = add(functor);
      ++update.added;
    }
    if (!l->declared) {
      l->declared = true;
      ++declared_factors;
    }
  }
  // Drops what the update since BeginUpdate left out.
  void Sweep() {
    for (Link& l : links) {
      if (!l.used || l.declared) continue;
      problem->RemoveResidualBlock(l.block);
      l = Link{};
      ++update.removed;
    }
    // A node's parameter blocks take its measurement factor with them.
    for (Wall& w : walls) {
      if (!w.used || w.declared) continue;
      problem->RemoveParameterBlock(w.n);
      problem->RemoveParameterBlock(&w.d);
      w = Wall{};
      ++update.removed;
    }
    for (Room& r : rooms) {
      if (!r.used || r.declared) continue;
      problem->RemoveParameterBlock(r.p);
      r = Room{};
      ++update.removed;
    }
    for (std::size_t i = 0; i < origins.size(); ++i) {
      Origin& o = origins[i];
      if (i == self || o.declared) continue;
      if (o.in_problem) {
        problem->RemoveParameterBlock(o.q);  // and its gravity factor
        problem->RemoveParameterBlock(o.t);
      }
      o = Origin{};
    }
    for (Origin& o : origins) o.moved = false;
  }
};

}  // namespace msgraphs::core
