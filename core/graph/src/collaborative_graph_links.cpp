// SPDX-License-Identifier: MIT
// The collaborative graph's links (collaborative_graph.hpp): wall to wall, room to its walls,
// room to room (a corridor across its axis), and an origin's own measurements.
#include <cmath>

#include "collaborative_graph_impl.hpp"

namespace msgraphs::core {
using namespace collab_factors;  // NOLINT: the functors of this one graph

Status CollaborativeGraph::AddWallWall(std::uint32_t a, std::uint32_t b) {
  Impl& m = *impl_;
  if (a >= m.walls.size() || b >= m.walls.size() || a == b || !m.walls[a].declared || !m.walls[b].declared)
    return Error{Errc::kNotFound, "collaborative graph: wall-wall needs two wall nodes"};
  Impl::Wall& A = m.walls[a];
  Impl::Wall& B = m.walls[b];
  const Impl::Link* known = m.FindLink(Impl::Kind::kWallSame, a, b);
  if (known != nullptr && known->declared) return Ok();
  if (auto s = m.HasRoomForFactors(1); !s) return s;
  m.DeclareLink(Impl::Kind::kWallSame, a, b,
                WallSame{1.0 / m.config.wall_same_sigma_rad, 1.0 / m.config.wall_same_sigma_m},
                [&](WallSame* f) {
                  return m.problem->AddResidualBlock(new ceres::AutoDiffCostFunction<WallSame, 4, 3, 1, 3, 1>(f),
                                                     m.huber.get(), A.n, &A.d, B.n, &B.d);
                });
  ++m.origins[A.robot].factors;
  if (B.robot != A.robot) ++m.origins[B.robot].factors;
  return Ok();
}

Status CollaborativeGraph::AddRoomWalls(std::uint32_t room, std::uint32_t wall_a, std::uint32_t wall_b) {
  Impl& m = *impl_;
  if (room >= m.rooms.size() || !m.rooms[room].declared || wall_a >= m.walls.size() || wall_b >= m.walls.size() ||
      wall_a == wall_b || !m.walls[wall_a].declared || !m.walls[wall_b].declared)
    return Error{Errc::kNotFound, "collaborative graph: room-to-wall needs a room and two wall nodes"};
  Impl::Room& R = m.rooms[room];
  Impl::Wall& A = m.walls[wall_a];
  Impl::Wall& B = m.walls[wall_b];
  if (A.robot != R.robot || B.robot != R.robot)
    return Error{Errc::kInvalidArgument, "collaborative graph: a room's walls are its own robot's"};
  // As its robot measured them: facing each other (within 15 degrees), the centre between.
  const Eigen::Vector3d& c = R.functor->centre;
  const DistilledWall& a = A.measured;
  const DistilledWall& b = B.measured;
  if (!(a.normal.dot(b.normal) < -std::cos(15.0 * M_PI / 180.0)) || !(a.normal.dot(c) + a.d > 0) ||
      !(b.normal.dot(c) + b.d > 0)) {
    return Error{Errc::kInvalidArgument, "collaborative graph: the walls do not face each other across the room"};
  }
  const Impl::Link* known = m.FindLink(Impl::Kind::kRoomWalls, room, wall_a, wall_b);
  if (known != nullptr && known->declared) return Ok();
  if (auto s = m.HasRoomForFactors(1); !s) return s;
  m.DeclareLink(
      Impl::Kind::kRoomWalls, room, wall_a, RoomBetweenWalls{1.0 / m.config.room_wall_sigma_m},
      [&](RoomBetweenWalls* f) {
        return m.problem->AddResidualBlock(new ceres::AutoDiffCostFunction<RoomBetweenWalls, 1, 3, 3, 1, 3, 1>(f),
                                           m.huber.get(), R.p, A.n, &A.d, B.n, &B.d);
      },
      wall_b);
  ++m.origins[R.robot].factors;
  return Ok();
}

Status CollaborativeGraph::AddRoomRoom(std::uint32_t a, std::uint32_t b) {
  Impl& m = *impl_;
  if (a >= m.rooms.size() || b >= m.rooms.size() || a == b || !m.rooms[a].declared || !m.rooms[b].declared)
    return Error{Errc::kNotFound, "collaborative graph: room-room needs two room nodes"};
  Impl::Room& A = m.rooms[a];
  Impl::Room& B = m.rooms[b];
  const bool corridor = A.corridor || B.corridor;
  const Impl::Kind kind = !corridor ? Impl::Kind::kRoomSame : A.corridor ? Impl::Kind::kCorridorA : Impl::Kind::kCorridorB;
  const Impl::Link* known = m.FindLink(kind, a, b);
  if (known != nullptr && known->declared) return Ok();
  if (auto s = m.HasRoomForFactors(A.robot != B.robot ? 2 : 1); !s) return s;
  if (corridor) {
    // Either robot's corridor axis will do: the yaw factor below turns them together.
    const Impl::Room& C = A.corridor ? A : B;
    m.DeclareLink(kind, a, b, CorridorSame{C.yaw_rad, 1.0 / m.config.room_same_sigma_m}, [&](CorridorSame* f) {
      return m.problem->AddResidualBlock(new ceres::AutoDiffCostFunction<CorridorSame, 2, 4, 3, 3>(f),
                                         m.huber.get(), m.origins[C.robot].q, A.p, B.p);
    });
  } else {
    m.DeclareLink(kind, a, b, RoomSame{1.0 / m.config.room_same_sigma_m}, [&](RoomSame* f) {
      return m.problem->AddResidualBlock(new ceres::AutoDiffCostFunction<RoomSame, 3, 3, 3>(f), m.huber.get(),
                                         A.p, B.p);
    });
  }
  if (A.robot != B.robot) {
    m.DeclareLink(Impl::Kind::kRoomYaw, a, b, RoomYaw{A.yaw_rad, B.yaw_rad, 1.0 / m.config.room_yaw_sigma_rad},
                  [&](RoomYaw* f) {
                    return m.problem->AddResidualBlock(new ceres::AutoDiffCostFunction<RoomYaw, 1, 4, 4>(f),
                                                       m.huber.get(), m.origins[A.robot].q, m.origins[B.robot].q);
                  });
  }
  ++m.origins[A.robot].factors;
  if (B.robot != A.robot) ++m.origins[B.robot].factors;
  return Ok();
}

Status CollaborativeGraph::AddOriginMeasurement(std::uint16_t robot_b,
                                                const Eigen::Isometry3d& T,
                                                double sigma_m,
                                                double sigma_rad) {
  Impl& m = *impl_;
  Impl::Origin* o = m.Get(robot_b);
  if (o == nullptr || robot_b == m.self)
    return Error{Errc::kNotFound, "collaborative graph: robot without an initial origin"};
  if (!T.matrix().allFinite() || !(sigma_m > 0) || !(sigma_rad > 0)) {
    return Error{Errc::kInvalidArgument,
                 "collaborative graph: origin measurement not finite or sigma not positive"};
  }
  if (auto s = m.HasRoomForFactors(1); !s) return s;
  m.Use(robot_b);
  m.DeclareLink(Impl::Kind::kOrigin, robot_b, o->origin_ordinal++,
                OriginMeasured{Eigen::Quaterniond(T.linear()).normalized(), T.translation(), 1.0 / sigma_m,
                               1.0 / sigma_rad},
                [&](OriginMeasured* f) {
                  return m.problem->AddResidualBlock(new ceres::AutoDiffCostFunction<OriginMeasured, 6, 4, 3>(f),
                                                     m.huber.get(), o->q, o->t);
                });
  ++o->factors;
  return Ok();
}

Status CollaborativeGraph::AddSameFloor(std::uint16_t robot_b, const Eigen::Vector3d& floor_point_b,
                                        double floor_z_self, double sigma_m) {
  Impl& m = *impl_;
  Impl::Origin* o = m.Get(robot_b);
  if (o == nullptr || robot_b == m.self)
    return Error{Errc::kNotFound, "collaborative graph: robot without an initial origin"};
  if (!floor_point_b.allFinite() || !std::isfinite(floor_z_self) || !(sigma_m > 0))
    return Error{Errc::kInvalidArgument, "collaborative graph: floor not finite or sigma not positive"};
  if (auto s = m.HasRoomForFactors(1); !s) return s;
  m.Use(robot_b);
  m.DeclareLink(Impl::Kind::kFloor, robot_b, o->floor_ordinal++, SameFloor{floor_point_b, floor_z_self, 1.0 / sigma_m},
                [&](SameFloor* f) {
                  return m.problem->AddResidualBlock(new ceres::AutoDiffCostFunction<SameFloor, 1, 4, 3>(f),
                                                     m.huber.get(), o->q, o->t);
                });
  ++o->factors;
  return Ok();
}

}  // namespace msgraphs::core
