// SPDX-License-Identifier: MIT
#include "msgraphs/core/graph/collaborative_graph.hpp"

#include <ceres/ceres.h>

#include <cmath>
#include <vector>

#include "s_graph_factors.hpp"

namespace msgraphs::core {
namespace {

// Origins: Eigen quaternion (x, y, z, w) and translation; p_self = R p_robot + t.
template <typename T>
Eigen::Matrix<T, 3, 3> Rotation(const T* q) {
  return Eigen::Quaternion<T>(q[3], q[0], q[1], q[2]).toRotationMatrix();
}

// A wall node (n, d in self's frame) against what its robot measured: the S-Graph's
// keyframe-to-plane factor (sgraph::PlaneResidual) with the robot's origin as the "keyframe".

struct WallSame {
  double inv_sigma_rad, inv_sigma_m;
  template <typename T>
  bool operator()(const T* n_a, const T* d_a, const T* n_b, const T* d_b, T* r) const {
    for (int i = 0; i < 3; ++i) r[i] = (n_b[i] - n_a[i]) * T(inv_sigma_rad);
    r[3] = (d_b[0] - d_a[0]) * T(inv_sigma_m);
    return true;
  }
};

// A room node (centre in self's frame) against its robot's measurement (robot frame).
struct RoomMeasured {
  Eigen::Vector3d centre;
  double inv_sigma;
  template <typename T>
  bool operator()(const T* q, const T* t, const T* p, T* r) const {
    const Eigen::Matrix<T, 3, 3> R = Rotation(q);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> p_self(p), t_self(t);
    const Eigen::Matrix<T, 3, 1> e = R.transpose() * (p_self - t_self) - centre.cast<T>();
    for (int i = 0; i < 3; ++i) r[i] = e[i] * T(inv_sigma);
    return true;
  }
};

struct RoomSame {
  double inv_sigma;
  template <typename T>
  bool operator()(const T* p_a, const T* p_b, T* r) const {
    for (int i = 0; i < 3; ++i) r[i] = (p_b[i] - p_a[i]) * T(inv_sigma);
    return true;
  }
};

// Two nodes of the same corridor: the same line across, the same floor; nothing along. A
// corridor's centre along its length is the centroid of whatever stretch its robot saw, so
// two robots' centres differ along it by up to the corridor's length (a 1 cm tie there slid a
// merged origin 7.6 m along a corridor, benchmark m011). The across axis is the corridor's
// room-frame x axis (the normal of its wall pair) through its robot's origin.
struct CorridorSame {
  double yaw_rad, inv_sigma;
  template <typename T>
  bool operator()(const T* q, const T* p_a, const T* p_b, T* r) const {
    const Eigen::Matrix<T, 3, 1> across =
        Rotation(q) * Eigen::Matrix<T, 3, 1>(T(std::cos(yaw_rad)), T(std::sin(yaw_rad)), T(0));
    const Eigen::Matrix<T, 3, 1> e(p_b[0] - p_a[0], p_b[1] - p_a[1], p_b[2] - p_a[2]);
    r[0] = across.dot(e) * T(inv_sigma);
    r[1] = e[2] * T(inv_sigma);
    return true;
  }
};

// The two rooms' x axes (each robot's measured yaw through its origin) agree up to quarter
// turns: sin(4 delta) / 4 is delta near each of them.
struct RoomYaw {
  double yaw_a, yaw_b, inv_sigma;
  template <typename T>
  bool operator()(const T* q_a, const T* q_b, T* r) const {
    const Eigen::Matrix<T, 3, 1> x_a =
        Rotation(q_a) * Eigen::Matrix<T, 3, 1>(T(std::cos(yaw_a)), T(std::sin(yaw_a)), T(0));
    const Eigen::Matrix<T, 3, 1> x_b =
        Rotation(q_b) * Eigen::Matrix<T, 3, 1>(T(std::cos(yaw_b)), T(std::sin(yaw_b)), T(0));
    const T delta = atan2(x_a[0] * x_b[1] - x_a[1] * x_b[0], x_a[0] * x_b[0] + x_a[1] * x_b[1]);
    r[0] = sin(T(4.0) * delta) / T(4.0) * T(inv_sigma);
    return true;
  }
};

struct Gravity {
  double inv_sigma;
  template <typename T>
  bool operator()(const T* q, T* r) const {
    const Eigen::Matrix<T, 3, 3> R = Rotation(q);
    r[0] = R(0, 2) * T(inv_sigma);
    r[1] = R(1, 2) * T(inv_sigma);
    return true;
  }
};

struct OriginMeasured {
  Eigen::Quaterniond q_m;
  Eigen::Vector3d t_m;
  double inv_sigma_m, inv_sigma_rad;
  template <typename T>
  bool operator()(const T* q, const T* t, T* r) const {
    const Eigen::Quaternion<T> e =
        q_m.conjugate().cast<T>() * Eigen::Quaternion<T>(q[3], q[0], q[1], q[2]);
    const T sign = e.w() < T(0) ? T(-1) : T(1);
    for (int i = 0; i < 3; ++i) {
      r[i] = T(2.0) * sign * e.vec()[i] * T(inv_sigma_rad);
      r[3 + i] = (t[i] - T(t_m[i])) * T(inv_sigma_m);
    }
    return true;
  }
};

// Two robots walk the same floor: robot b's floor point, through its origin, is at self's
// floor height. Vertical walls say nothing of heights, and their normals' slight tilts would
// otherwise let the origin's height wander.
struct SameFloor {
  Eigen::Vector3d p_b;  // a point on robot b's floor, its map frame
  double z_self, inv_sigma;
  template <typename T>
  bool operator()(const T* q, const T* t, T* r) const {
    const Eigen::Matrix<T, 3, 1> p = Rotation(q) * p_b.cast<T>() + Eigen::Matrix<T, 3, 1>(t[0], t[1], t[2]);
    r[0] = (p[2] - T(z_self)) * T(inv_sigma);
    return true;
  }
};

}  // namespace

Status CollaborativeGraphConfig::Validate() const {
  const bool positive = room_sigma_m > 0 && room_same_sigma_m > 0 && room_yaw_sigma_rad > 0 &&
                        wall_sigma_floor_m > 0 && wall_sigma_floor_rad > 0 &&
                        wall_same_sigma_m > 0 && wall_same_sigma_rad > 0 && gravity_sigma_rad > 0 &&
                        huber > 0;
  if (max_robots < 2 || max_walls < 1 || max_rooms < 1 || max_factors < 1 || !positive ||
      max_iterations < 1) {
    return Error{Errc::kInvalidConfig, "collaborative graph: sigmas and limits must be positive"};
  }
  return Ok();
}

struct CollaborativeGraph::Impl {
  CollaborativeGraphConfig config;
  std::uint16_t self = 0;
  std::unique_ptr<ceres::Problem> problem;
  std::unique_ptr<ceres::LossFunction> huber;
  ceres::EigenQuaternionManifold quaternion_manifold;
  ceres::SphereManifold<3> sphere_manifold;
  struct Origin {
    double q[4] = {0, 0, 0, 1};
    double t[3] = {0, 0, 0};
    bool known = false;
    bool in_problem = false;
    std::size_t factors = 0;
  };
  struct Wall {
    std::uint16_t robot = 0;
    DistilledWall measured;  // in its robot's frame
    double n[3] = {1, 0, 0};
    double d = 0;
  };
  struct Room {
    std::uint16_t robot = 0;
    std::uint32_t id = 0;
    double yaw_rad = 0;
    bool corridor = false;
    double p[3] = {0, 0, 0};
  };
  std::vector<Origin> origins;
  std::vector<Wall> walls;
  std::vector<Room> rooms;
  std::size_t factors = 0;
  // Solve snapshots (sized at Init).
  std::vector<double> backup;

  void Reset() {
    ceres::Problem::Options options;
    options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    problem = std::make_unique<ceres::Problem>(options);
    for (Origin& o : origins) {
      o.in_problem = false;
      o.factors = 0;
    }
    walls.clear();
    rooms.clear();
    factors = 0;
  }
  Origin* Get(std::uint16_t robot) {
    if (robot >= origins.size() || !origins[robot].known) return nullptr;
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
  Status HasRoomForFactor() const {
    if (factors >= config.max_factors)
      return Error{Errc::kCapacityExceeded, "collaborative graph: factor store full"};
    return Ok();
  }
};

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
  // Node addresses must not move once Ceres holds them: reserve the capacities.
  m.walls.reserve(config.max_walls);
  m.rooms.reserve(config.max_rooms);
  m.backup.resize(config.max_robots * 7 + config.max_walls * 4 + config.max_rooms * 3);
  m.Reset();
  m.origins[self].known = true;
  return Ok();
}

void CollaborativeGraph::Clear() {
  Impl& m = *impl_;
  for (std::size_t i = 0; i < m.origins.size(); ++i) {
    if (i != m.self) m.origins[i] = Impl::Origin{};
  }
  m.Reset();
}

Status CollaborativeGraph::SetInitial(std::uint16_t robot, const Eigen::Isometry3d& T) {
  Impl& m = *impl_;
  if (robot >= m.origins.size())
    return Error{Errc::kCapacityExceeded, "collaborative graph: robot id beyond max_robots"};
  if (robot == m.self) return Error{Errc::kInvalidArgument, "collaborative graph: self is fixed"};
  if (!T.matrix().allFinite())
    return Error{Errc::kInvalidArgument, "collaborative graph: initial origin not finite"};
  Impl::Origin& o = m.origins[robot];
  const Eigen::Quaterniond q(T.linear());
  o.q[0] = q.x();
  o.q[1] = q.y();
  o.q[2] = q.z();
  o.q[3] = q.w();
  for (int i = 0; i < 3; ++i) o.t[i] = T.translation()[i];
  o.known = true;
  return Ok();
}

Expected<std::uint32_t> CollaborativeGraph::AddWall(std::uint16_t robot, const DistilledWall& w) {
  Impl& m = *impl_;
  Impl::Origin* o = m.Get(robot);
  if (o == nullptr)
    return Error{Errc::kNotFound, "collaborative graph: robot without an initial origin"};
  for (std::size_t i = 0; i < m.walls.size(); ++i) {
    if (m.walls[i].robot == robot && m.walls[i].measured.id == w.id)
      return static_cast<std::uint32_t>(i);
  }
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
  if (m.walls.size() >= m.config.max_walls)
    return Error{Errc::kCapacityExceeded, "collaborative graph: wall store full"};
  if (auto s = m.HasRoomForFactor(); !s) return s.error();
  m.Use(robot);
  Impl::Wall& node = m.walls.emplace_back();
  node.robot = robot;
  node.measured = w;
  const Eigen::Isometry3d T = m.Pose(robot);
  const Eigen::Vector3d n = T.linear() * w.normal;
  for (int i = 0; i < 3; ++i) node.n[i] = n[i];
  node.d = w.d - n.dot(T.translation());
  Eigen::Vector3d u, v;
  WallBasis(w.normal, u, v);
  const Eigen::Matrix3d sqrt_information = llt.matrixU();
  m.problem->AddParameterBlock(node.n, 3, &m.sphere_manifold);
  m.problem->AddResidualBlock(new ceres::AutoDiffCostFunction<sgraph::PlaneResidual, 3, 4, 3, 3, 1>(
                                  new sgraph::PlaneResidual{u, v, w.d, sqrt_information}),
                              m.huber.get(), o->q, o->t, node.n, &node.d);
  ++o->factors;
  ++m.factors;
  return static_cast<std::uint32_t>(m.walls.size() - 1);
}

Expected<std::uint32_t> CollaborativeGraph::AddRoom(std::uint16_t robot,
                                                    const DistilledRoom& room,
                                                    double floor_z_m) {
  Impl& m = *impl_;
  Impl::Origin* o = m.Get(robot);
  if (o == nullptr)
    return Error{Errc::kNotFound, "collaborative graph: robot without an initial origin"};
  for (std::size_t i = 0; i < m.rooms.size(); ++i) {
    if (m.rooms[i].robot == robot && m.rooms[i].id == room.id) return static_cast<std::uint32_t>(i);
  }
  if (!room.centre.allFinite() || !std::isfinite(room.yaw_rad) || !std::isfinite(floor_z_m))
    return Error{Errc::kInvalidArgument, "collaborative graph: room not finite"};
  if (m.rooms.size() >= m.config.max_rooms)
    return Error{Errc::kCapacityExceeded, "collaborative graph: room store full"};
  if (auto s = m.HasRoomForFactor(); !s) return s.error();
  m.Use(robot);
  Impl::Room& node = m.rooms.emplace_back();
  node.robot = robot;
  node.id = room.id;
  node.yaw_rad = room.yaw_rad;
  node.corridor = room.shape == RoomShape::kCorridor;
  const Eigen::Vector3d centre(room.centre.x(), room.centre.y(), floor_z_m);
  const Eigen::Vector3d p = m.Pose(robot) * centre;
  for (int i = 0; i < 3; ++i) node.p[i] = p[i];
  m.problem->AddResidualBlock(new ceres::AutoDiffCostFunction<RoomMeasured, 3, 4, 3, 3>(
                                  new RoomMeasured{centre, 1.0 / m.config.room_sigma_m}),
                              m.huber.get(), o->q, o->t, node.p);
  ++o->factors;
  ++m.factors;
  return static_cast<std::uint32_t>(m.rooms.size() - 1);
}

Status CollaborativeGraph::AddWallWall(std::uint32_t a, std::uint32_t b) {
  Impl& m = *impl_;
  if (a >= m.walls.size() || b >= m.walls.size() || a == b)
    return Error{Errc::kNotFound, "collaborative graph: wall-wall needs two wall nodes"};
  if (auto s = m.HasRoomForFactor(); !s) return s;
  Impl::Wall& A = m.walls[a];
  Impl::Wall& B = m.walls[b];
  m.problem->AddResidualBlock(
      new ceres::AutoDiffCostFunction<WallSame, 4, 3, 1, 3, 1>(
          new WallSame{1.0 / m.config.wall_same_sigma_rad, 1.0 / m.config.wall_same_sigma_m}),
      m.huber.get(), A.n, &A.d, B.n, &B.d);
  ++m.origins[A.robot].factors;
  if (B.robot != A.robot) ++m.origins[B.robot].factors;
  ++m.factors;
  return Ok();
}

Status CollaborativeGraph::AddRoomRoom(std::uint32_t a, std::uint32_t b) {
  Impl& m = *impl_;
  if (a >= m.rooms.size() || b >= m.rooms.size() || a == b)
    return Error{Errc::kNotFound, "collaborative graph: room-room needs two room nodes"};
  if (m.factors + 2 > m.config.max_factors)
    return Error{Errc::kCapacityExceeded, "collaborative graph: factor store full"};
  Impl::Room& A = m.rooms[a];
  Impl::Room& B = m.rooms[b];
  if (A.corridor || B.corridor) {
    // Either robot's corridor axis will do: the yaw factor below turns them together.
    const Impl::Room& C = A.corridor ? A : B;
    m.problem->AddResidualBlock(new ceres::AutoDiffCostFunction<CorridorSame, 2, 4, 3, 3>(
                                    new CorridorSame{C.yaw_rad, 1.0 / m.config.room_same_sigma_m}),
                                m.huber.get(), m.origins[C.robot].q, A.p, B.p);
  } else {
    m.problem->AddResidualBlock(new ceres::AutoDiffCostFunction<RoomSame, 3, 3, 3>(
                                    new RoomSame{1.0 / m.config.room_same_sigma_m}),
                                m.huber.get(), A.p, B.p);
  }
  if (A.robot != B.robot) {
    m.problem->AddResidualBlock(new ceres::AutoDiffCostFunction<RoomYaw, 1, 4, 4>(new RoomYaw{
                                    A.yaw_rad, B.yaw_rad, 1.0 / m.config.room_yaw_sigma_rad}),
                                m.huber.get(), m.origins[A.robot].q, m.origins[B.robot].q);
    ++m.factors;
  }
  ++m.origins[A.robot].factors;
  if (B.robot != A.robot) ++m.origins[B.robot].factors;
  ++m.factors;
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
  if (auto s = m.HasRoomForFactor(); !s) return s;
  m.Use(robot_b);
  m.problem->AddResidualBlock(
      new ceres::AutoDiffCostFunction<OriginMeasured, 6, 4, 3>(
          new OriginMeasured{Eigen::Quaterniond(T.linear()).normalized(), T.translation(),
                             1.0 / sigma_m, 1.0 / sigma_rad}),
      m.huber.get(), o->q, o->t);
  ++o->factors;
  ++m.factors;
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
  if (auto s = m.HasRoomForFactor(); !s) return s;
  m.Use(robot_b);
  m.problem->AddResidualBlock(new ceres::AutoDiffCostFunction<SameFloor, 1, 4, 3>(
                                  new SameFloor{floor_point_b, floor_z_self, 1.0 / sigma_m}),
                              m.huber.get(), o->q, o->t);
  ++o->factors;
  ++m.factors;
  return Ok();
}

Expected<double> CollaborativeGraph::Solve() {
  Impl& m = *impl_;
  if (m.factors == 0) return 0.0;
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

std::size_t CollaborativeGraph::walls() const { return impl_->walls.size(); }
std::size_t CollaborativeGraph::rooms() const { return impl_->rooms.size(); }

DistilledWall CollaborativeGraph::wall(std::uint32_t handle) const {
  const Impl::Wall& w = impl_->walls.at(handle);
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
