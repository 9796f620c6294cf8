// SPDX-License-Identifier: MIT
#include "msgraphs/core/graph/collaborative_graph.hpp"

#include <ceres/ceres.h>

#include <cmath>
#include <vector>

namespace msgraphs::core {
namespace {

// Point b of robot b's map in map a: R(theta) b + t, with origin = [x, y, theta].
template <typename T>
Eigen::Matrix<T, 2, 1> ToA(const T* origin, const Eigen::Vector2d& b) {
  const T c = cos(origin[2]), s = sin(origin[2]);
  return {c * T(b.x()) - s * T(b.y()) + origin[0], s * T(b.x()) + c * T(b.y()) + origin[1]};
}

struct RoomRoomResidual {
  Eigen::Vector2d centre_a, centre_b;
  double yaw_a, yaw_b, inv_sigma, inv_sigma_yaw;
  template <typename T>
  bool operator()(const T* origin, T* r) const {
    const Eigen::Matrix<T, 2, 1> b = ToA(origin, centre_b);
    r[0] = (T(centre_a.x()) - b[0]) * T(inv_sigma);
    r[1] = (T(centre_a.y()) - b[1]) * T(inv_sigma);
    // Room frames are defined up to quarter turns: sin(4 d) / 4 is d near each of them.
    r[2] = sin(T(4.0) * (T(yaw_a) - T(yaw_b) - origin[2])) / T(4.0) * T(inv_sigma_yaw);
    return true;
  }
};

struct WallWallResidual {
  Eigen::Vector2d n_a, n_b;
  double d_a, d_b, inv_sigma_angle, inv_sigma_offset;
  template <typename T>
  bool operator()(const T* origin, T* r) const {
    const T c = cos(origin[2]), s = sin(origin[2]);
    const Eigen::Matrix<T, 2, 1> n(c * T(n_b.x()) - s * T(n_b.y()),
                                   s * T(n_b.x()) + c * T(n_b.y()));
    // n.p + d_b = 0 in map b becomes n'.p' + (d_b - n'.t) = 0 in map a.
    const T d = T(d_b) - n[0] * origin[0] - n[1] * origin[1];
    r[0] =
        (T(n_a.x()) * n[1] - T(n_a.y()) * n[0]) * T(inv_sigma_angle);  // sine of the angle between
    r[1] = (T(d_a) - d) * T(inv_sigma_offset);
    return true;
  }
};

struct OriginResidual {
  double x, y, yaw, inv_sigma, inv_sigma_yaw;
  template <typename T>
  bool operator()(const T* origin, T* r) const {
    r[0] = (origin[0] - T(x)) * T(inv_sigma);
    r[1] = (origin[1] - T(y)) * T(inv_sigma);
    r[2] = sin(origin[2] - T(yaw)) * T(inv_sigma_yaw);
    return true;
  }
};

}  // namespace

Status CollaborativeGraphConfig::Validate() const {
  if (max_robots < 1 || max_factors < 1 || !(room_sigma_m > 0) || !(room_yaw_sigma_rad > 0) ||
      !(wall_sigma_floor_m > 0) || !(wall_sigma_floor_rad > 0) || !(huber > 0) ||
      max_iterations < 1) {
    return Error{Errc::kInvalidConfig, "collaborative graph: sigmas and limits must be positive"};
  }
  return Ok();
}

struct CollaborativeGraph::Impl {
  CollaborativeGraphConfig config;
  std::unique_ptr<ceres::Problem> problem;
  std::unique_ptr<ceres::LossFunction> huber;
  struct Robot {
    double origin[3] = {0, 0, 0};
    bool known = false;
    std::size_t factors = 0;
  };
  std::vector<Robot> robots;
  std::size_t factors = 0;

  void Reset() {
    ceres::Problem::Options options;
    options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    problem = std::make_unique<ceres::Problem>(options);
    for (Robot& r : robots) r.factors = 0;
    factors = 0;
  }
  Robot* Get(std::uint16_t robot) {
    if (robot >= robots.size() || !robots[robot].known) return nullptr;
    return &robots[robot];
  }
};

CollaborativeGraph::CollaborativeGraph() : impl_(std::make_unique<Impl>()) {}
CollaborativeGraph::~CollaborativeGraph() = default;

Status CollaborativeGraph::Init(const CollaborativeGraphConfig& config) {
  if (auto s = config.Validate(); !s) return s;
  impl_->config = config;
  impl_->huber = std::make_unique<ceres::HuberLoss>(config.huber);
  impl_->robots.assign(config.max_robots, Impl::Robot{});
  impl_->Reset();
  return Ok();
}

void CollaborativeGraph::Clear() {
  for (Impl::Robot& r : impl_->robots) r = Impl::Robot{};
  impl_->Reset();
}

Status CollaborativeGraph::SetInitial(std::uint16_t robot, const Eigen::Isometry3d& T) {
  if (robot >= impl_->robots.size())
    return Error{Errc::kCapacityExceeded, "collaborative graph: robot id beyond max_robots"};
  if (!T.matrix().allFinite())
    return Error{Errc::kInvalidArgument, "collaborative graph: initial origin not finite"};
  Impl::Robot& r = impl_->robots[robot];
  r.origin[0] = T.translation().x();
  r.origin[1] = T.translation().y();
  r.origin[2] = std::atan2(T.linear()(1, 0), T.linear()(0, 0));
  r.known = true;
  return Ok();
}

Status CollaborativeGraph::AddRoomRoom(std::uint16_t robot_b,
                                       const Eigen::Vector2d& centre_a,
                                       double yaw_a,
                                       const Eigen::Vector2d& centre_b,
                                       double yaw_b) {
  Impl& m = *impl_;
  Impl::Robot* r = m.Get(robot_b);
  if (r == nullptr)
    return Error{Errc::kNotFound, "collaborative graph: robot without an initial origin"};
  if (!centre_a.allFinite() || !centre_b.allFinite() || !std::isfinite(yaw_a) ||
      !std::isfinite(yaw_b)) {
    return Error{Errc::kInvalidArgument, "collaborative graph: room not finite"};
  }
  if (m.factors >= m.config.max_factors)
    return Error{Errc::kCapacityExceeded, "collaborative graph: factor store full"};
  auto* cost = new ceres::AutoDiffCostFunction<RoomRoomResidual, 3, 3>(
      new RoomRoomResidual{centre_a, centre_b, yaw_a, yaw_b, 1.0 / m.config.room_sigma_m,
                           1.0 / m.config.room_yaw_sigma_rad});
  m.problem->AddResidualBlock(cost, m.huber.get(), r->origin);
  ++r->factors;
  ++m.factors;
  return Ok();
}

Status CollaborativeGraph::AddWallWall(std::uint16_t robot_b,
                                       const DistilledWall& a,
                                       const DistilledWall& b) {
  Impl& m = *impl_;
  Impl::Robot* r = m.Get(robot_b);
  if (r == nullptr)
    return Error{Errc::kNotFound, "collaborative graph: robot without an initial origin"};
  const double na = a.normal.head<2>().norm(), nb = b.normal.head<2>().norm();
  if (!(na > 0.5) || !(nb > 0.5) || !std::isfinite(a.d) || !std::isfinite(b.d)) {
    return Error{Errc::kInvalidArgument, "collaborative graph: wall not vertical or not finite"};
  }
  if (m.factors >= m.config.max_factors)
    return Error{Errc::kCapacityExceeded, "collaborative graph: factor store full"};
  const double sigma_angle =
      std::sqrt(a.covariance(0, 0) + b.covariance(0, 0) +
                m.config.wall_sigma_floor_rad * m.config.wall_sigma_floor_rad);
  const double sigma_offset = std::sqrt(a.covariance(2, 2) + b.covariance(2, 2) +
                                        m.config.wall_sigma_floor_m * m.config.wall_sigma_floor_m);
  auto* cost = new ceres::AutoDiffCostFunction<WallWallResidual, 2, 3>(
      new WallWallResidual{a.normal.head<2>() / na, b.normal.head<2>() / nb, a.d / na, b.d / nb,
                           1.0 / sigma_angle, 1.0 / sigma_offset});
  m.problem->AddResidualBlock(cost, m.huber.get(), r->origin);
  ++r->factors;
  ++m.factors;
  return Ok();
}

Status CollaborativeGraph::AddOriginMeasurement(std::uint16_t robot_b,
                                                const Eigen::Isometry3d& T,
                                                double sigma_m,
                                                double sigma_rad) {
  Impl& m = *impl_;
  Impl::Robot* r = m.Get(robot_b);
  if (r == nullptr)
    return Error{Errc::kNotFound, "collaborative graph: robot without an initial origin"};
  if (!T.matrix().allFinite() || !(sigma_m > 0) || !(sigma_rad > 0)) {
    return Error{Errc::kInvalidArgument,
                 "collaborative graph: origin measurement not finite or sigma not positive"};
  }
  if (m.factors >= m.config.max_factors)
    return Error{Errc::kCapacityExceeded, "collaborative graph: factor store full"};
  auto* cost = new ceres::AutoDiffCostFunction<OriginResidual, 3, 3>(new OriginResidual{
      T.translation().x(), T.translation().y(), std::atan2(T.linear()(1, 0), T.linear()(0, 0)),
      1.0 / sigma_m, 1.0 / sigma_rad});
  m.problem->AddResidualBlock(cost, m.huber.get(), r->origin);
  ++r->factors;
  ++m.factors;
  return Ok();
}

Expected<double> CollaborativeGraph::Solve() {
  Impl& m = *impl_;
  if (m.factors == 0) return 0.0;
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = m.config.max_iterations;
  options.num_threads = 1;
  options.logging_type = ceres::SILENT;
  double backup[64][3];
  const std::size_t n = std::min<std::size_t>(m.robots.size(), 64);
  for (std::size_t i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) backup[i][k] = m.robots[i].origin[k];
  }
  ceres::Solver::Summary summary;
  ceres::Solve(options, m.problem.get(), &summary);
  bool finite = std::isfinite(summary.final_cost);
  for (std::size_t i = 0; i < n; ++i) {
    for (double v : m.robots[i].origin) finite = finite && std::isfinite(v);
  }
  if (!finite || summary.termination_type == ceres::FAILURE) {
    for (std::size_t i = 0; i < n; ++i) {
      for (int k = 0; k < 3; ++k) m.robots[i].origin[k] = backup[i][k];
    }
    return Error{Errc::kNotConverged, "collaborative graph: solve failed; origins kept"};
  }
  return summary.final_cost;
}

bool CollaborativeGraph::has_robot(std::uint16_t robot) const {
  return robot < impl_->robots.size() && impl_->robots[robot].known;
}

Eigen::Isometry3d CollaborativeGraph::T_self_robot(std::uint16_t robot) const {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  if (!has_robot(robot)) return T;
  const double* o = impl_->robots[robot].origin;
  T.linear() = Eigen::AngleAxisd(o[2], Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() << o[0], o[1], 0;
  return T;
}

std::size_t CollaborativeGraph::factors(std::uint16_t robot) const {
  return robot < impl_->robots.size() ? impl_->robots[robot].factors : 0;
}

}  // namespace msgraphs::core
