// SPDX-License-Identifier: MIT
#include "msgraphs/core/graph/collaborative_graph.hpp"

#include <cmath>

#include "collaborative_graph_impl.hpp"

namespace msgraphs::core {
using namespace collab_factors;  // NOLINT: the functors of this one graph

Status CollaborativeGraphConfig::Validate() const {
  const bool positive = room_sigma_m > 0 && room_same_sigma_m > 0 && room_yaw_sigma_rad > 0 &&
                        wall_sigma_floor_m > 0 && wall_sigma_floor_rad > 0 &&
                        wall_same_sigma_m > 0 && wall_same_sigma_rad > 0 && gravity_sigma_rad > 0 &&
                        room_wall_sigma_m > 0 && huber > 0;
  if (max_robots < 2 || max_walls < 1 || max_rooms < 1 || max_factors < 1 || !positive ||
      max_iterations < 1) {
    return Error{Errc::kInvalidConfig, "collaborative graph: sigmas and limits must be positive"};
  }
  return Ok();
}


CollaborativeGraph::CollaborativeGraph() : impl_(std::make_unique<Impl>()) {}
CollaborativeGraph::~CollaborativeGraph() = default;

Status CollaborativeGraph::Init(const CollaborativeGraphConfig& config, std::uint16_t self) {
  if (auto s = config.Validate(); !s) return s;
  if (self == 0 || self >= config.max_robots)
    return Error{Errc::kInvalidConfig, "collaborative graph: self robot id beyond max_robots"};
  Impl& m = *impl_;
  m.config = config;
  m.self = self;
  m.huber = std::make_unique<ceres::HuberLoss>(config.huber);
  m.origins.assign(config.max_robots, Impl::Origin{});
  m.walls.assign(2 * config.max_walls, Impl::Wall{});
  m.rooms.assign(2 * config.max_rooms, Impl::Room{});
  m.links.assign(2 * config.max_factors, Impl::Link{});
  m.backup.resize(config.max_robots * 7 + m.walls.size() * 4 + m.rooms.size() * 3);
  m.Reset();
  m.origins[self].known = m.origins[self].declared = true;
  m.declared_walls = m.declared_rooms = m.declared_factors = 0;
  m.update = {};
  return Ok();
}

void CollaborativeGraph::BeginUpdate() {
  Impl& m = *impl_;
  for (std::size_t i = 0; i < m.origins.size(); ++i) {
    Impl::Origin& o = m.origins[i];
    o.declared = i == m.self;
    o.moved = false;
    o.factors = 0;
    o.origin_ordinal = o.floor_ordinal = 0;
  }
  for (Impl::Wall& w : m.walls) w.declared = false;
  for (Impl::Room& r : m.rooms) r.declared = false;
  for (Impl::Link& l : m.links) l.declared = false;
  m.declared_walls = m.declared_rooms = m.declared_factors = 0;
  m.update = {};
}

Status CollaborativeGraph::SetInitial(std::uint16_t robot, const Eigen::Isometry3d& T) {
  Impl& m = *impl_;
  if (robot >= m.origins.size())
    return Error{Errc::kCapacityExceeded, "collaborative graph: robot id beyond max_robots"};
  if (robot == m.self) return Error{Errc::kInvalidArgument, "collaborative graph: self is fixed"};
  if (!T.matrix().allFinite())
    return Error{Errc::kInvalidArgument, "collaborative graph: initial origin not finite"};
  Impl::Origin& o = m.origins[robot];
  // The estimate it already holds (read back and set again) stays bit for bit, with its nodes:
  // the next solve starts where the last one ended.
  const bool same = o.known && (m.Pose(robot).translation() - T.translation()).norm() < 1e-9 &&
                    Eigen::AngleAxisd(m.Pose(robot).linear().transpose() * T.linear()).angle() < 1e-9;
  if (!same) {
    const Eigen::Quaterniond q(T.linear());
    o.q[0] = q.x();
    o.q[1] = q.y();
    o.q[2] = q.z();
    o.q[3] = q.w();
    for (int i = 0; i < 3; ++i) o.t[i] = T.translation()[i];
    o.moved = o.known;
  }
  o.known = o.declared = true;
  return Ok();
}

Expected<std::uint32_t> CollaborativeGraph::AddWall(std::uint16_t robot, const DistilledWall& w) {
  Impl& m = *impl_;
  Impl::Origin* o = m.Get(robot);
  if (o == nullptr)
    return Error{Errc::kNotFound, "collaborative graph: robot without an initial origin"};
  std::size_t slot = m.walls.size();
  for (std::size_t i = 0; i < m.walls.size(); ++i) {
    if (m.walls[i].used && m.walls[i].robot == robot && m.walls[i].measured.id == w.id) slot = i;
  }
  // Declared once per update: the first declaration's measurement holds.
  if (slot < m.walls.size() && m.walls[slot].declared) return static_cast<std::uint32_t>(slot);
  if (!w.normal.allFinite() || std::fabs(w.normal.norm() - 1.0) > 1e-3 || !std::isfinite(w.d) ||
      !w.covariance.allFinite()) {
    return Error{Errc::kInvalidArgument, "collaborative graph: wall not finite or not unit"};
  }
  const double floor_m = m.config.wall_sigma_floor_m, floor_rad = m.config.wall_sigma_floor_rad;
  Eigen::Matrix3d covariance = w.covariance;
  covariance.diagonal() +=
      Eigen::Vector3d(floor_rad * floor_rad, floor_rad * floor_rad, floor_m * floor_m);
  Eigen::LLT<Eigen::Matrix3d> llt(covariance.inverse());
  if (llt.info() != Eigen::Success)
    return Error{Errc::kInvalidArgument, "collaborative graph: wall covariance not definite"};
  if (m.declared_walls >= m.config.max_walls)
    return Error{Errc::kCapacityExceeded, "collaborative graph: wall store full"};
  if (auto s = m.HasRoomForFactors(1); !s) return s.error();
  Eigen::Vector3d u, v;
  WallBasis(w.normal, u, v);
  const sgraph::PlaneResidual measurement{u, v, w.d, llt.matrixU()};
  const bool added = slot == m.walls.size();
  if (added) {
    // Twice the capacity, at most max_walls declared: a slot is free.
    for (slot = 0; m.walls[slot].used; ++slot) {
    }
  }
  Impl::Wall& node = m.walls[slot];
  node.measured = w;
  if (added || o->moved) {
    // Starts from what its robot measured, through the origin.
    const Eigen::Isometry3d T = m.Pose(robot);
    const Eigen::Vector3d n = T.linear() * w.normal;
    for (int i = 0; i < 3; ++i) node.n[i] = n[i];
    node.d = w.d - n.dot(T.translation());
  }
  if (added) {
    m.Use(robot);
    node.used = true;
    node.robot = robot;
    node.functor = new sgraph::PlaneResidual(measurement);
    m.problem->AddParameterBlock(node.n, 3, &m.sphere_manifold);
    m.problem->AddResidualBlock(new ceres::AutoDiffCostFunction<sgraph::PlaneResidual, 3, 4, 3, 3, 1>(node.functor),
                                m.huber.get(), o->q, o->t, node.n, &node.d);
    ++m.update.added;
  } else {
    *node.functor = measurement;
    ++m.update.kept;
  }
  node.declared = true;
  ++m.declared_walls;
  ++m.declared_factors;
  ++o->factors;
  return static_cast<std::uint32_t>(slot);
}

Expected<std::uint32_t> CollaborativeGraph::AddRoom(std::uint16_t robot,
                                                    const DistilledRoom& room,
                                                    double floor_z_m) {
  Impl& m = *impl_;
  Impl::Origin* o = m.Get(robot);
  if (o == nullptr)
    return Error{Errc::kNotFound, "collaborative graph: robot without an initial origin"};
  std::size_t slot = m.rooms.size();
  for (std::size_t i = 0; i < m.rooms.size(); ++i) {
    if (m.rooms[i].used && m.rooms[i].robot == robot && m.rooms[i].id == room.id) slot = i;
  }
  if (slot < m.rooms.size() && m.rooms[slot].declared) return static_cast<std::uint32_t>(slot);
  if (!room.centre.allFinite() || !std::isfinite(room.yaw_rad) || !std::isfinite(floor_z_m))
    return Error{Errc::kInvalidArgument, "collaborative graph: room not finite"};
  if (m.declared_rooms >= m.config.max_rooms)
    return Error{Errc::kCapacityExceeded, "collaborative graph: room store full"};
  if (auto s = m.HasRoomForFactors(1); !s) return s.error();
  const Eigen::Vector3d centre(room.centre.x(), room.centre.y(), floor_z_m);
  const RoomMeasured measurement{centre, 1.0 / m.config.room_sigma_m};
  const bool added = slot == m.rooms.size();
  if (added) {
    for (slot = 0; m.rooms[slot].used; ++slot) {
    }
  }
  Impl::Room& node = m.rooms[slot];
  node.yaw_rad = room.yaw_rad;
  node.corridor = room.shape == RoomShape::kCorridor;
  if (added || o->moved) {
    const Eigen::Vector3d p = m.Pose(robot) * centre;
    for (int i = 0; i < 3; ++i) node.p[i] = p[i];
  }
  if (added) {
    m.Use(robot);
    node.used = true;
    node.robot = robot;
    node.id = room.id;
    node.functor = new RoomMeasured(measurement);
    m.problem->AddResidualBlock(new ceres::AutoDiffCostFunction<RoomMeasured, 3, 4, 3, 3>(node.functor),
                                m.huber.get(), o->q, o->t, node.p);
    ++m.update.added;
  } else {
    *node.functor = measurement;
    ++m.update.kept;
  }
  node.declared = true;
  ++m.declared_rooms;
  ++m.declared_factors;
  ++o->factors;
  return static_cast<std::uint32_t>(slot);
}

Expected<double> CollaborativeGraph::Solve() {
  Impl& m = *impl_;
  m.Sweep();
  if (m.declared_factors == 0) return 0.0;
  // Snapshot every value, to restore after a failed solve.
  std::size_t at = 0;
  auto save = [&](const double* p, int n) {
    for (int i = 0; i < n; ++i) m.backup[at++] = p[i];
  };
  for (const Impl::Origin& o : m.origins) save(o.q, 4), save(o.t, 3);
  for (const Impl::Wall& w : m.walls) save(w.n, 3), save(&w.d, 1);
  for (const Impl::Room& r : m.rooms) save(r.p, 3);

  ceres::Solver::Options options;
  options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  options.max_num_iterations = m.config.max_iterations;
  options.num_threads = 1;
  options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(options, m.problem.get(), &summary);

  bool finite = std::isfinite(summary.final_cost);
  for (const Impl::Origin& o : m.origins) {
    for (double v : o.q) finite = finite && std::isfinite(v);
    for (double v : o.t) finite = finite && std::isfinite(v);
  }
  for (const Impl::Wall& w : m.walls)
    finite = finite && std::isfinite(w.d) && std::isfinite(w.n[0]);
  for (const Impl::Room& r : m.rooms) finite = finite && std::isfinite(r.p[0]);
  if (!finite || summary.termination_type == ceres::FAILURE) {
    at = 0;
    auto load = [&](double* p, int n) {
      for (int i = 0; i < n; ++i) p[i] = m.backup[at++];
    };
    for (Impl::Origin& o : m.origins) load(o.q, 4), load(o.t, 3);
    for (Impl::Wall& w : m.walls) load(w.n, 3), load(&w.d, 1);
    for (Impl::Room& r : m.rooms) load(r.p, 3);
    return Error{Errc::kNotConverged, "collaborative graph: solve failed; values kept"};
  }
  return summary.final_cost;
}

const CollaborativeGraphUpdate& CollaborativeGraph::last_update() const { return impl_->update; }

std::uint16_t CollaborativeGraph::self() const { return impl_->self; }

bool CollaborativeGraph::has_robot(std::uint16_t robot) const {
  return robot < impl_->origins.size() && impl_->origins[robot].known;
}

Eigen::Isometry3d CollaborativeGraph::T_self_robot(std::uint16_t robot) const {
  if (!has_robot(robot)) return Eigen::Isometry3d::Identity();
  return impl_->Pose(robot);
}

std::size_t CollaborativeGraph::factors(std::uint16_t robot) const {
  return robot < impl_->origins.size() ? impl_->origins[robot].factors : 0;
}

std::size_t CollaborativeGraph::walls() const { return impl_->declared_walls; }
std::size_t CollaborativeGraph::rooms() const { return impl_->declared_rooms; }

DistilledWall CollaborativeGraph::wall(std::uint32_t handle) const {
  const Impl::Wall& w = impl_->walls.at(handle);  // a slot never used reads as a default wall
  DistilledWall out = w.measured;
  out.normal = Eigen::Vector3d(w.n[0], w.n[1], w.n[2]).normalized();
  out.d = w.d;
  const Eigen::Isometry3d T = impl_->Pose(w.robot);
  out.a = (T * Eigen::Vector3d(w.measured.a.x(), w.measured.a.y(), 0)).head<2>();
  out.b = (T * Eigen::Vector3d(w.measured.b.x(), w.measured.b.y(), 0)).head<2>();
  return out;
}
std::uint16_t CollaborativeGraph::wall_robot(std::uint32_t handle) const {
  return impl_->walls.at(handle).robot;
}

Eigen::Vector3d CollaborativeGraph::room_centre(std::uint32_t handle) const {
  const Impl::Room& r = impl_->rooms.at(handle);
  return {r.p[0], r.p[1], r.p[2]};
}
std::uint16_t CollaborativeGraph::room_robot(std::uint32_t handle) const {
  return impl_->rooms.at(handle).robot;
}

}  // namespace msgraphs::core
