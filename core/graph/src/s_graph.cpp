// SPDX-License-Identifier: MIT
#include "msgraphs/core/graph/s_graph.hpp"

#include <ceres/ceres.h>
#include <ceres/sphere_manifold.h>

#include <Eigen/Cholesky>
#include <cmath>
#include <vector>

#include "msgraphs/core/geometry/se3.hpp"
#include "msgraphs/core/graph/distilled_graph.hpp"
#include "s_graph_factors.hpp"

namespace msgraphs::core {
namespace {

constexpr std::int32_t kNone = -1;

enum class FactorKind : std::uint8_t {
  kRelative,
  kPlane,
  kRoom,
  kWallWall,
  kFloorRoom,
  kPlanePrior
};

struct KeyframeNode {
  double q[4] = {0, 0, 0, 1};  // Eigen order: x y z w
  double t[3] = {0, 0, 0};
  double stamp_s = 0;
  std::int32_t prev = kNone, next = kNone;  // neighbours in time among active keyframes
  std::uint32_t loop_factors = 0;
  // Every relative-pose measurement from `prev` to this keyframe fused into one (information-
  // weighted in the tangent space) with the summed information: what a composed factor is
  // made of when a keyframe between them is sparsified. Measurements, not estimates: an
  // estimate taken before the next full solve would bake its error into the graph.
  Eigen::Isometry3d measurement_from_prev = Eigen::Isometry3d::Identity();
  Matrix6d information_from_prev = Matrix6d::Zero();
  bool active = false;
};

struct PlaneNode {
  double n[3] = {1, 0, 0};
  double d[1] = {0};
  MapPlane info;
  bool in_problem = false;
};

struct RoomNode {
  double c[2] = {0, 0};
  MapRoom info;
  std::int32_t factor = kNone;
  std::int32_t floor_factor = kNone;
  bool in_problem = false;
};

struct FactorRecord {
  FactorKind kind = FactorKind::kRelative;
  RelativePoseKind relative = RelativePoseKind::kOdometry;
  std::uint32_t a = 0, b = 0;  // keyframes, keyframe and plane, planes, room, floor and room
  ceres::ResidualBlockId id = nullptr;
  bool active = false;
};

bool SqrtInformation6(const Matrix6d& information, Matrix6d& sqrt_information) {
  if (!information.allFinite() || !information.isApprox(information.transpose(), 1e-6))
    return false;
  Eigen::LLT<Matrix6d> llt(information);
  if (llt.info() != Eigen::Success) return false;
  sqrt_information = llt.matrixU();
  return sqrt_information.allFinite();
}

// Adjoint of T for tangent vectors ordered [translation; rotation].
Matrix6d Adjoint(const Eigen::Isometry3d& T) {
  Matrix6d A = Matrix6d::Zero();
  const Eigen::Matrix3d R = T.linear();
  const Eigen::Vector3d t = T.translation();
  Eigen::Matrix3d tx;
  tx << 0, -t.z(), t.y(), t.z(), 0, -t.x(), -t.y(), t.x(), 0;
  A.topLeftCorner<3, 3>() = R;
  A.topRightCorner<3, 3>() = tx * R;
  A.bottomRightCorner<3, 3>() = R;
  return A;
}

}  // namespace

Status SGraphConfig::Validate() const {
  if (max_keyframes < 8 || max_planes < 1 || max_rooms < 1 || max_factors < 16) {
    return Error{Errc::kInvalidConfig,
                 "s-graph capacities too small (keyframes >= 8, factors >= 16)"};
  }
  if (!(huber_relative_pose > 0) || !(huber_loop_closure > 0) || !(huber_plane > 0) ||
      !(huber_room > 0)) {
    return Error{Errc::kInvalidConfig, "s-graph Huber thresholds must be positive"};
  }
  if (!(room_sigma_m > 0) || !(wall_wall_sigma > 0) || !(floor_room_sigma_m > 0)) {
    return Error{Errc::kInvalidConfig, "s-graph sigmas must be positive"};
  }
  if (local_window_keyframes < 2 || local_window_keyframes >= max_keyframes) {
    return Error{Errc::kInvalidConfig, "s-graph local window must be >= 2 and below max_keyframes"};
  }
  if (local_max_iterations < 1 || full_max_iterations < 1 || !(local_max_seconds > 0) ||
      !(full_max_seconds > 0)) {
    return Error{Errc::kInvalidConfig, "s-graph solve limits must be positive"};
  }
  return Ok();
}

struct SGraph::Impl {
  SGraphConfig config;
  std::unique_ptr<ceres::Problem> problem;
  ceres::EigenQuaternionManifold quaternion_manifold;
  ceres::SphereManifold<3> sphere_manifold;
  std::unique_ptr<ceres::LossFunction> huber_relative, huber_loop, huber_plane, huber_room;

  std::vector<KeyframeNode> keyframes;
  std::vector<std::int32_t> free_keyframe_slots;
  std::size_t keyframe_high_water = 0;  // slots ever used
  std::int32_t newest = kNone, origin = kNone;
  std::size_t active_keyframes = 0;

  std::vector<PlaneNode> planes;
  std::size_t plane_count = 0;
  std::vector<RoomNode> rooms;
  std::size_t room_count = 0;
  double floor_c[2] = {0, 0};
  bool floor_active = false;

  std::vector<FactorRecord> factors;
  std::vector<std::int32_t> free_factor_slots;
  std::size_t factor_high_water = 0, active_factors = 0;

  std::vector<double> snapshot;  // parameter values before a solve, to undo a bad one
  SGraphStats stats;

  bool ValidKeyframe(std::uint32_t id) const {
    return id < keyframe_high_water && keyframes[id].active;
  }
  bool ValidPlane(std::uint32_t id) const { return id < plane_count && planes[id].info.active; }
  bool ValidRoom(std::uint32_t id) const { return id < room_count && rooms[id].info.active; }

  Eigen::Isometry3d Pose(std::uint32_t id) const {
    const KeyframeNode& k = keyframes[id];
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::Quaterniond(k.q[3], k.q[0], k.q[1], k.q[2]).normalized().toRotationMatrix();
    T.translation() = Eigen::Vector3d(k.t[0], k.t[1], k.t[2]);
    return T;
  }

  Expected<std::int32_t> NewFactor(FactorKind kind, std::uint32_t a, std::uint32_t b) {
    std::int32_t slot = kNone;
    if (!free_factor_slots.empty()) {
      slot = free_factor_slots.back();
      free_factor_slots.pop_back();
    } else if (factor_high_water < factors.size()) {
      slot = static_cast<std::int32_t>(factor_high_water++);
    } else {
      ++stats.rejected_capacity;
      return Error{Errc::kCapacityExceeded, "s-graph factor store full"};
    }
    FactorRecord& f = factors[static_cast<std::size_t>(slot)];
    f = FactorRecord{};
    f.kind = kind;
    f.a = a;
    f.b = b;
    f.active = true;
    ++active_factors;
    stats.factors_peak = std::max(stats.factors_peak, active_factors);
    return slot;
  }

  // Forgets a factor record (the residual block is removed by the caller or by Ceres).
  void DropFactor(std::int32_t slot) {
    FactorRecord& f = factors[static_cast<std::size_t>(slot)];
    if (!f.active) return;
    f.active = false;
    --active_factors;
    switch (f.kind) {
      case FactorKind::kRelative:
        --stats.relative_factors[static_cast<std::size_t>(f.relative)];
        if (f.relative == RelativePoseKind::kLoopClosure) {
          if (keyframes[f.a].loop_factors > 0) --keyframes[f.a].loop_factors;
          if (keyframes[f.b].loop_factors > 0) --keyframes[f.b].loop_factors;
        }
        break;
      case FactorKind::kPlane:
        --stats.plane_factors;
        break;
      case FactorKind::kRoom:
        --stats.room_factors;
        break;
      case FactorKind::kWallWall:
        --stats.wall_wall_factors;
        break;
      case FactorKind::kFloorRoom:
        --stats.floor_factors;
        break;
      case FactorKind::kPlanePrior:
        --stats.plane_prior_factors;
        break;
    }
    free_factor_slots.push_back(slot);  // capacity reserved at Init: no allocation
  }

  void RemoveFactor(std::int32_t slot) {
    FactorRecord& f = factors[static_cast<std::size_t>(slot)];
    if (!f.active) return;
    problem->RemoveResidualBlock(f.id);
    DropFactor(slot);
  }

  void EnsurePlaneInProblem(PlaneNode& p) {
    if (p.in_problem) return;
    problem->AddParameterBlock(p.n, 3, &sphere_manifold);
    problem->AddParameterBlock(p.d, 1);
    p.in_problem = true;
  }

  Expected<std::uint32_t> AddRelative(std::uint32_t from,
                                      std::uint32_t to,
                                      const Eigen::Isometry3d& T_from_to,
                                      const Matrix6d& information,
                                      RelativePoseKind kind) {
    if (!ValidKeyframe(from) || !ValidKeyframe(to) || from == to) {
      ++stats.rejected_missing_node;
      return Error{Errc::kNotFound, "relative pose between missing keyframes"};
    }
    if (!IsValidRigidTransform(T_from_to, 1e-6)) {
      ++stats.rejected_pose;
      return Error{Errc::kInvalidArgument, "relative pose is not a finite rigid transform"};
    }
    Matrix6d sqrt_information;
    if (!SqrtInformation6(information, sqrt_information)) {
      ++stats.rejected_information;
      return Error{Errc::kInvalidArgument,
                   "relative pose information is not symmetric positive definite"};
    }
    auto slot = NewFactor(FactorKind::kRelative, from, to);
    if (!slot) return slot.error();
    auto* functor =
        new sgraph::RelativePoseResidual{Eigen::Quaterniond(T_from_to.linear()).normalized(),
                                         T_from_to.translation(), sqrt_information};
    auto* cost =
        new ceres::AutoDiffCostFunction<sgraph::RelativePoseResidual, 6, 4, 3, 4, 3>(functor);
    ceres::LossFunction* loss =
        kind == RelativePoseKind::kLoopClosure ? huber_loop.get() : huber_relative.get();
    FactorRecord& f = factors[static_cast<std::size_t>(*slot)];
    f.relative = kind;
    f.id = problem->AddResidualBlock(cost, loss, keyframes[from].q, keyframes[from].t,
                                     keyframes[to].q, keyframes[to].t);
    ++stats.relative_factors[static_cast<std::size_t>(kind)];
    if (kind == RelativePoseKind::kLoopClosure) {
      ++keyframes[from].loop_factors;
      ++keyframes[to].loop_factors;
    } else if (keyframes[to].prev == static_cast<std::int32_t>(from)) {
      KeyframeNode& node = keyframes[to];
      if (node.information_from_prev.isZero()) {
        node.measurement_from_prev = T_from_to;
      } else {
        const Vector6d xi = Se3Log(node.measurement_from_prev.inverse() * T_from_to);
        const Vector6d step =
            (node.information_from_prev + information).ldlt().solve(information * xi);
        if (step.allFinite())
          node.measurement_from_prev = node.measurement_from_prev * Se3Exp(step);
      }
      node.information_from_prev += information;
    }
    return static_cast<std::uint32_t>(*slot);
  }

  // Removes the keyframe whose loss costs least: not the origin, not in the local window, not
  // an end of a loop closure, and with the shortest hop between its neighbours (the most
  // redundant). Its neighbours are joined by the composition of its relative-pose chain.
  bool Sparsify() {
    std::int32_t window_start = newest;
    for (std::size_t i = 1; i < config.local_window_keyframes && window_start != kNone; ++i) {
      window_start = keyframes[static_cast<std::size_t>(window_start)].prev;
    }
    std::int32_t victim = kNone;
    double best = 1e300;
    for (std::int32_t k = keyframes[static_cast<std::size_t>(origin)].next;
         k != kNone && k != window_start; k = keyframes[static_cast<std::size_t>(k)].next) {
      const KeyframeNode& node = keyframes[static_cast<std::size_t>(k)];
      if (node.loop_factors > 0 || node.prev == kNone || node.next == kNone) continue;
      const double hop = (Pose(static_cast<std::uint32_t>(node.prev)).translation() -
                          Pose(static_cast<std::uint32_t>(node.next)).translation())
                             .norm();
      if (hop < best) {
        best = hop;
        victim = k;
      }
    }
    if (victim == kNone) return false;
    const auto v = static_cast<std::uint32_t>(victim);
    KeyframeNode& node = keyframes[v];
    const auto p = static_cast<std::uint32_t>(node.prev), n = static_cast<std::uint32_t>(node.next);
    // Composition Z = Z_a Z_b of the fused measurements of each hop, with right perturbations:
    // Sigma_Z = Ad(Z_b^-1) Sigma_a Ad(Z_b^-1)^T + Sigma_b.
    const Eigen::Isometry3d Z_a = node.measurement_from_prev,
                            Z_b = keyframes[n].measurement_from_prev;
    const Matrix6d info_a = node.information_from_prev, info_b = keyframes[n].information_from_prev;
    Matrix6d composed_information = Matrix6d::Identity() * 1e-6;
    bool have_information = false;
    if (info_a.determinant() > 0 && info_b.determinant() > 0) {
      const Matrix6d Ad = Adjoint(Z_b.inverse());
      const Matrix6d sigma = Ad * info_a.inverse() * Ad.transpose() + info_b.inverse();
      composed_information = sigma.inverse();
      composed_information = 0.5 * (composed_information + composed_information.transpose()).eval();
      have_information = composed_information.allFinite();
    }
    // Detach: forget every factor record on the victim, then let Ceres drop its residuals.
    for (std::size_t i = 0; i < factor_high_water; ++i) {
      const FactorRecord& f = factors[i];
      if (!f.active) continue;
      const bool touches = (f.kind == FactorKind::kRelative && (f.a == v || f.b == v)) ||
                           (f.kind == FactorKind::kPlane && f.a == v);
      if (touches) DropFactor(static_cast<std::int32_t>(i));
    }
    problem->RemoveParameterBlock(node.q);
    problem->RemoveParameterBlock(node.t);
    node.active = false;
    keyframes[p].next = static_cast<std::int32_t>(n);
    keyframes[n].prev = static_cast<std::int32_t>(p);
    keyframes[n].information_from_prev.setZero();
    free_keyframe_slots.push_back(victim);
    --active_keyframes;
    ++stats.sparsified;
    if (have_information) {
      static_cast<void>(
          AddRelative(p, n, Z_a * Z_b, composed_information, RelativePoseKind::kSparsified));
    }
    return true;
  }

  // Every parameter value in one flat buffer (sized at Init), to undo a solve.
  void Snapshot(bool restore) {
    std::size_t i = 0;
    auto io = [&](double* v, int size) {
      for (int k = 0; k < size; ++k, ++i) {
        if (restore)
          v[k] = snapshot[i];
        else
          snapshot[i] = v[k];
      }
    };
    for (std::size_t k = 0; k < keyframe_high_water; ++k) {
      io(keyframes[k].q, 4);
      io(keyframes[k].t, 3);
    }
    for (std::size_t k = 0; k < plane_count; ++k) {
      io(planes[k].n, 3);
      io(planes[k].d, 1);
    }
    for (std::size_t k = 0; k < room_count; ++k) io(rooms[k].c, 2);
    io(floor_c, 2);
  }

  bool StateFinite() const {
    for (std::size_t k = 0; k < keyframe_high_water; ++k) {
      for (double v : keyframes[k].q)
        if (!std::isfinite(v)) return false;
      for (double v : keyframes[k].t)
        if (!std::isfinite(v)) return false;
    }
    for (std::size_t k = 0; k < plane_count; ++k) {
      for (double v : planes[k].n)
        if (!std::isfinite(v)) return false;
      if (!std::isfinite(planes[k].d[0])) return false;
    }
    for (std::size_t k = 0; k < room_count; ++k) {
      if (!std::isfinite(rooms[k].c[0]) || !std::isfinite(rooms[k].c[1])) return false;
    }
    return std::isfinite(floor_c[0]) && std::isfinite(floor_c[1]);
  }

  void SetFree(double* block, bool free) {
    if (!problem->HasParameterBlock(block)) return;
    const bool constant = problem->IsParameterBlockConstant(block);
    if (free && constant) problem->SetParameterBlockVariable(block);
    if (!free && !constant) problem->SetParameterBlockConstant(block);
  }
};

SGraph::SGraph() : impl_(std::make_unique<Impl>()) {}
SGraph::~SGraph() = default;

Status SGraph::Init(const SGraphConfig& config) {
  if (auto s = config.Validate(); !s) return s;
  Impl& m = *impl_;
  m.config = config;
  ceres::Problem::Options options;
  options.cost_function_ownership = ceres::TAKE_OWNERSHIP;
  options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  options.enable_fast_removal = true;  // sparsification and room updates remove blocks
  m.problem = std::make_unique<ceres::Problem>(options);
  m.huber_relative = std::make_unique<ceres::HuberLoss>(config.huber_relative_pose);
  m.huber_loop = std::make_unique<ceres::HuberLoss>(config.huber_loop_closure);
  m.huber_plane = std::make_unique<ceres::HuberLoss>(config.huber_plane);
  m.huber_room = std::make_unique<ceres::HuberLoss>(config.huber_room);
  // One spare slot: AddKeyframe sparsifies after the new keyframe exists.
  m.keyframes.assign(config.max_keyframes + 1, KeyframeNode{});
  m.free_keyframe_slots.clear();
  m.free_keyframe_slots.reserve(config.max_keyframes + 1);
  m.keyframe_high_water = 0;
  m.newest = m.origin = kNone;
  m.active_keyframes = 0;
  m.planes.assign(config.max_planes, PlaneNode{});
  m.plane_count = 0;
  m.rooms.assign(config.max_rooms, RoomNode{});
  m.room_count = 0;
  m.floor_active = false;
  m.factors.assign(config.max_factors, FactorRecord{});
  m.free_factor_slots.clear();
  m.free_factor_slots.reserve(config.max_factors);
  m.factor_high_water = m.active_factors = 0;
  m.snapshot.assign(
      (config.max_keyframes + 1) * 7 + config.max_planes * 4 + config.max_rooms * 2 + 2, 0.0);
  m.stats = SGraphStats{};
  m.stats.store_bytes =
      m.keyframes.size() * sizeof(KeyframeNode) + m.planes.size() * sizeof(PlaneNode) +
      m.rooms.size() * sizeof(RoomNode) + m.factors.size() * sizeof(FactorRecord) +
      m.snapshot.size() * sizeof(double) +
      (m.free_keyframe_slots.capacity() + m.free_factor_slots.capacity()) * sizeof(std::int32_t);
  return Ok();
}

Expected<std::uint32_t> SGraph::AddKeyframe(double stamp_s,
                                            const Eigen::Isometry3d& T_map_keyframe) {
  Impl& m = *impl_;
  if (!m.problem) return Error{Errc::kInvalidArgument, "s-graph not initialised"};
  if (!std::isfinite(stamp_s) || !IsValidRigidTransform(T_map_keyframe, 1e-6)) {
    ++m.stats.rejected_pose;
    return Error{Errc::kInvalidArgument, "keyframe pose or stamp is not finite / not rigid"};
  }
  if (m.newest != kNone && !(stamp_s > m.keyframes[static_cast<std::size_t>(m.newest)].stamp_s)) {
    ++m.stats.rejected_stamp;
    return Error{Errc::kOutOfOrder, "keyframe stamp not after the previous keyframe's"};
  }
  std::int32_t slot = kNone;
  if (!m.free_keyframe_slots.empty()) {
    slot = m.free_keyframe_slots.back();
    m.free_keyframe_slots.pop_back();
  } else {
    slot = static_cast<std::int32_t>(m.keyframe_high_water++);
  }
  KeyframeNode& k = m.keyframes[static_cast<std::size_t>(slot)];
  k = KeyframeNode{};
  const Eigen::Quaterniond q(T_map_keyframe.linear());
  k.q[0] = q.x();
  k.q[1] = q.y();
  k.q[2] = q.z();
  k.q[3] = q.w();
  for (int i = 0; i < 3; ++i) k.t[i] = T_map_keyframe.translation()[i];
  k.stamp_s = stamp_s;
  k.prev = m.newest;
  k.active = true;
  if (m.newest != kNone) m.keyframes[static_cast<std::size_t>(m.newest)].next = slot;
  m.newest = slot;
  m.problem->AddParameterBlock(k.q, 4, &m.quaternion_manifold);
  m.problem->AddParameterBlock(k.t, 3);
  if (m.origin == kNone) {
    // The gauge: the first keyframe is the map's origin and never moves.
    m.origin = slot;
    m.problem->SetParameterBlockConstant(k.q);
    m.problem->SetParameterBlockConstant(k.t);
  }
  ++m.active_keyframes;
  if (m.active_keyframes > m.config.max_keyframes) static_cast<void>(m.Sparsify());
  m.stats.keyframes_peak = std::max(m.stats.keyframes_peak, m.active_keyframes);
  return static_cast<std::uint32_t>(slot);
}

Expected<std::uint32_t> SGraph::AddRelativePose(std::uint32_t from,
                                                std::uint32_t to,
                                                const Eigen::Isometry3d& T_from_to,
                                                const Matrix6d& information,
                                                RelativePoseKind kind) {
  return impl_->AddRelative(from, to, T_from_to, information, kind);
}

Expected<double> SGraph::FactorChi2(std::uint32_t factor) const {
  const Impl& m = *impl_;
  if (factor >= m.factor_high_water || !m.factors[factor].active)
    return Error{Errc::kNotFound, "no such factor"};
  double cost = 0;
  if (!m.problem->EvaluateResidualBlock(m.factors[factor].id, false, &cost, nullptr, nullptr)) {
    return Error{Errc::kDegenerate, "factor could not be evaluated"};
  }
  return 2.0 * cost;  // Ceres' cost is half the squared norm
}

Status SGraph::RemoveFactor(std::uint32_t factor) {
  Impl& m = *impl_;
  if (factor >= m.factor_high_water || !m.factors[factor].active)
    return Error{Errc::kNotFound, "no such factor"};
  const FactorKind kind = m.factors[factor].kind;
  if (kind == FactorKind::kRoom || kind == FactorKind::kFloorRoom) {
    return Error{Errc::kInvalidArgument,
                 "room factors go with their room (UpdateRoom / RemoveRoom)"};
  }
  m.RemoveFactor(static_cast<std::int32_t>(factor));
  return Ok();
}

Expected<std::uint32_t> SGraph::AddPlane(const Eigen::Vector3d& normal_map,
                                         double d_map,
                                         PlaneClass plane_class) {
  Impl& m = *impl_;
  if (!normal_map.allFinite() || !std::isfinite(d_map) || normal_map.norm() < 1e-6) {
    ++m.stats.rejected_pose;
    return Error{Errc::kInvalidArgument, "plane is not finite"};
  }
  if (m.plane_count >= m.planes.size()) {
    ++m.stats.rejected_capacity;
    return Error{Errc::kCapacityExceeded, "s-graph plane store full"};
  }
  PlaneNode& p = m.planes[m.plane_count];
  p = PlaneNode{};
  const double norm = normal_map.norm();
  for (int i = 0; i < 3; ++i) p.n[i] = normal_map[i] / norm;
  p.d[0] = d_map / norm;
  p.info.plane_class = plane_class;
  p.info.active = true;
  // A fixed basis of the plane for its information: horizontal u for walls (along the wall).
  WallBasis(Eigen::Vector3d(p.n[0], p.n[1], p.n[2]), p.info.basis_u, p.info.basis_v);
  return static_cast<std::uint32_t>(m.plane_count++);
}

Status SGraph::AddPlaneObservation(std::uint32_t keyframe,
                                   std::uint32_t plane,
                                   const PlaneMeasurement& z,
                                   double behind_margin_m) {
  Impl& m = *impl_;
  if (!m.ValidKeyframe(keyframe) || !m.ValidPlane(plane)) {
    ++m.stats.rejected_missing_node;
    return Error{Errc::kNotFound, "plane observation of a missing keyframe or plane"};
  }
  if (!z.normal.allFinite() || !std::isfinite(z.d) || !z.basis_u.allFinite() ||
      !z.basis_v.allFinite()) {
    ++m.stats.rejected_pose;
    return Error{Errc::kInvalidArgument, "plane measurement is not finite"};
  }
  Eigen::Matrix3d information;
  Eigen::Matrix3d sqrt_information;
  {
    if (!z.covariance.allFinite() || !z.covariance.isApprox(z.covariance.transpose(), 1e-6)) {
      ++m.stats.rejected_information;
      return Error{Errc::kInvalidArgument, "plane covariance not symmetric"};
    }
    Eigen::LLT<Eigen::Matrix3d> llt(z.covariance);
    if (llt.info() != Eigen::Success) {
      ++m.stats.rejected_information;
      return Error{Errc::kInvalidArgument, "plane covariance not positive definite"};
    }
    information = z.covariance.inverse();
    information = 0.5 * (information + information.transpose()).eval();
    Eigen::LLT<Eigen::Matrix3d> info_llt(information);
    if (info_llt.info() != Eigen::Success) {
      ++m.stats.rejected_information;
      return Error{Errc::kInvalidArgument, "plane information not positive definite"};
    }
    sqrt_information = info_llt.matrixU();
  }
  PlaneNode& p = m.planes[plane];
  const Eigen::Isometry3d T = m.Pose(keyframe);
  const Eigen::Vector3d n_map(p.n[0], p.n[1], p.n[2]);
  // Seen from behind: the keyframe stands behind the plane, or the measured normal points the
  // other way. Either means the other face of the wall (or a wrong association).
  const double signed_distance = n_map.dot(T.translation()) + p.d[0];
  const Eigen::Vector3d n_predicted = T.linear().transpose() * n_map;
  if (signed_distance < -behind_margin_m || n_predicted.dot(z.normal.normalized()) < 0.5) {
    ++m.stats.rejected_behind;
    return Error{Errc::kInvalidArgument, "plane seen from behind"};
  }
  auto slot = m.NewFactor(FactorKind::kPlane, keyframe, plane);
  if (!slot) return slot.error();
  m.EnsurePlaneInProblem(p);
  auto* functor = new sgraph::PlaneResidual{z.basis_u, z.basis_v, z.d, sqrt_information};
  auto* cost = new ceres::AutoDiffCostFunction<sgraph::PlaneResidual, 3, 4, 3, 3, 1>(functor);
  KeyframeNode& k = m.keyframes[keyframe];
  m.factors[static_cast<std::size_t>(*slot)].id =
      m.problem->AddResidualBlock(cost, m.huber_plane.get(), k.q, k.t, p.n, p.d);
  ++m.stats.plane_factors;
  // Information of this observation about the map plane: the Jacobian of the measurement
  // coordinates (u_m.n_k, v_m.n_k, d_k) with respect to the map plane's (alpha, beta, delta_d),
  // n_k = R^T n and d_k = d + n.t, at the keyframe's current estimate.
  Eigen::Matrix3d J = Eigen::Matrix3d::Zero();
  const Eigen::Vector3d ru = T.linear().transpose() * p.info.basis_u,
                        rv = T.linear().transpose() * p.info.basis_v;
  J << z.basis_u.dot(ru), z.basis_u.dot(rv), 0, z.basis_v.dot(ru), z.basis_v.dot(rv), 0,
      p.info.basis_u.dot(T.translation()), p.info.basis_v.dot(T.translation()), 1;
  p.info.information += J.transpose() * information * J;
  ++p.info.observations;
  p.info.last_keyframe = keyframe;
  return Ok();
}

Expected<std::uint32_t> SGraph::AddRoom(const MapRoom& room) {
  Impl& m = *impl_;
  if (m.room_count >= m.rooms.size()) {
    ++m.stats.rejected_capacity;
    return Error{Errc::kCapacityExceeded, "s-graph room store full"};
  }
  const auto id = static_cast<std::uint32_t>(m.room_count);
  RoomNode& r = m.rooms[id];
  r = RoomNode{};
  r.c[0] = room.centre.x();
  r.c[1] = room.centre.y();
  r.info = room;
  r.info.active = true;
  ++m.room_count;
  if (auto s = UpdateRoom(id, room); !s) {
    --m.room_count;
    r.info.active = false;
    return s.error();
  }
  return id;
}

Status SGraph::UpdateRoom(std::uint32_t id, const MapRoom& updated) {
  Impl& m = *impl_;
  if (!m.ValidRoom(id)) {
    ++m.stats.rejected_missing_node;
    return Error{Errc::kNotFound, "no such room"};
  }
  const int wall_count = updated.shape == RoomShape::kFourWall ? 4 : 2;
  for (int i = 0; i < wall_count; ++i) {
    const std::int32_t w = updated.walls[static_cast<std::size_t>(i)];
    if (w < 0 || !m.ValidPlane(static_cast<std::uint32_t>(w)) ||
        !m.planes[static_cast<std::size_t>(w)].in_problem) {
      ++m.stats.rejected_missing_node;
      return Error{Errc::kNotFound, "room wall is not an observed plane"};
    }
  }
  if (!updated.centre.allFinite() || !updated.corridor_anchor.allFinite()) {
    ++m.stats.rejected_pose;
    return Error{Errc::kInvalidArgument, "room centre not finite"};
  }
  RoomNode& r = m.rooms[id];
  if (r.factor != kNone) {
    m.RemoveFactor(r.factor);
    r.factor = kNone;
  }
  auto slot = m.NewFactor(FactorKind::kRoom, id, 0);
  if (!slot) return slot.error();
  if (!r.in_problem) {
    m.problem->AddParameterBlock(r.c, 2);
    r.in_problem = true;
  }
  const bool moved = (Eigen::Vector2d(r.c[0], r.c[1]) - updated.centre).norm() > 0.5;
  if (moved || r.info.shape != updated.shape) {
    r.c[0] = updated.centre.x();
    r.c[1] = updated.centre.y();
  }
  const double inv_sigma = 1.0 / m.config.room_sigma_m;
  auto W = [&](int i) -> PlaneNode& {
    return m.planes[static_cast<std::size_t>(updated.walls[static_cast<std::size_t>(i)])];
  };
  ceres::ResidualBlockId block = nullptr;
  if (updated.shape == RoomShape::kFourWall) {
    auto* cost =
        new ceres::AutoDiffCostFunction<sgraph::RoomResidual, 2, 2, 3, 1, 3, 1, 3, 1, 3, 1>(
            new sgraph::RoomResidual{inv_sigma});
    block = m.problem->AddResidualBlock(
        cost, m.huber_room.get(),
        {r.c, W(0).n, W(0).d, W(1).n, W(1).d, W(2).n, W(2).d, W(3).n, W(3).d});
  } else {
    auto* cost = new ceres::AutoDiffCostFunction<sgraph::CorridorResidual, 2, 2, 3, 1, 3, 1>(
        new sgraph::CorridorResidual{updated.corridor_anchor, inv_sigma});
    block =
        m.problem->AddResidualBlock(cost, m.huber_room.get(), r.c, W(0).n, W(0).d, W(1).n, W(1).d);
  }
  m.factors[static_cast<std::size_t>(*slot)].id = block;
  ++m.stats.room_factors;
  r.factor = *slot;
  const bool active = r.info.active;
  r.info = updated;
  r.info.active = active;
  return Ok();
}

Status SGraph::RemoveRoom(std::uint32_t id) {
  Impl& m = *impl_;
  if (!m.ValidRoom(id)) return Error{Errc::kNotFound, "no such room"};
  RoomNode& r = m.rooms[id];
  if (r.factor != kNone) m.RemoveFactor(r.factor);
  if (r.floor_factor != kNone) m.RemoveFactor(r.floor_factor);
  r.factor = r.floor_factor = kNone;
  if (r.in_problem) m.problem->RemoveParameterBlock(r.c);
  r.in_problem = false;
  r.info.active = false;
  return Ok();
}

Status SGraph::AddWallWall(std::uint32_t a, std::uint32_t b) {
  Impl& m = *impl_;
  if (a == b || !m.ValidPlane(a) || !m.ValidPlane(b) || !m.planes[a].in_problem ||
      !m.planes[b].in_problem) {
    ++m.stats.rejected_missing_node;
    return Error{Errc::kNotFound, "wall-wall factor between missing planes"};
  }
  const Eigen::Vector3d na(m.planes[a].n[0], m.planes[a].n[1], m.planes[a].n[2]);
  const Eigen::Vector3d nb(m.planes[b].n[0], m.planes[b].n[1], m.planes[b].n[2]);
  if (na.dot(nb) < 0.5) {
    ++m.stats.rejected_behind;
    return Error{Errc::kInvalidArgument, "wall-wall factor between opposite faces"};
  }
  auto slot = m.NewFactor(FactorKind::kWallWall, a, b);
  if (!slot) return slot.error();
  auto* cost = new ceres::AutoDiffCostFunction<sgraph::WallWallResidual, 4, 3, 1, 3, 1>(
      new sgraph::WallWallResidual{1.0 / m.config.wall_wall_sigma});
  m.factors[static_cast<std::size_t>(*slot)].id = m.problem->AddResidualBlock(
      cost, m.huber_plane.get(), m.planes[a].n, m.planes[a].d, m.planes[b].n, m.planes[b].d);
  ++m.stats.wall_wall_factors;
  return Ok();
}

Expected<std::uint32_t> SGraph::AddPlanePrior(const PlanePrior& prior) {
  Impl& m = *impl_;
  if (!m.ValidPlane(prior.plane) || !m.planes[prior.plane].in_problem) {
    ++m.stats.rejected_missing_node;
    return Error{Errc::kNotFound, "plane prior on a missing plane"};
  }
  if (!prior.normal.allFinite() || std::fabs(prior.normal.norm() - 1.0) > 1e-3 ||
      !std::isfinite(prior.d)) {
    ++m.stats.rejected_pose;
    return Error{Errc::kInvalidArgument, "plane prior not finite or not unit"};
  }
  Eigen::LLT<Eigen::Matrix3d> llt(prior.covariance);
  if (!prior.covariance.allFinite() || llt.info() != Eigen::Success) {
    ++m.stats.rejected_information;
    return Error{Errc::kInvalidArgument, "plane prior covariance not positive definite"};
  }
  PlaneNode& p = m.planes[prior.plane];
  const Eigen::Vector3d n(p.n[0], p.n[1], p.n[2]);
  if (n.dot(prior.normal) < 0.5) {
    ++m.stats.rejected_behind;
    return Error{Errc::kInvalidArgument, "plane prior facing the other way"};
  }
  Eigen::Matrix3d information = prior.covariance.inverse();
  information = 0.5 * (information + information.transpose()).eval();
  Eigen::LLT<Eigen::Matrix3d> info_llt(information);
  if (info_llt.info() != Eigen::Success) {
    ++m.stats.rejected_information;
    return Error{Errc::kInvalidArgument, "plane prior information not positive definite"};
  }
  auto slot = m.NewFactor(FactorKind::kPlanePrior, prior.plane, 0);
  if (!slot) return slot.error();
  Eigen::Vector3d u, v;
  WallBasis(prior.normal, u, v);
  auto* cost = new ceres::AutoDiffCostFunction<sgraph::PlanePriorResidual, 3, 3, 1>(
      new sgraph::PlanePriorResidual{u, v, prior.d, Eigen::Matrix3d(info_llt.matrixU())});
  m.factors[static_cast<std::size_t>(*slot)].id =
      m.problem->AddResidualBlock(cost, m.huber_plane.get(), p.n, p.d);
  ++m.stats.plane_prior_factors;
  return static_cast<std::uint32_t>(*slot);
}

Status SGraph::SetFloor(const Eigen::Vector2d& centre) {
  Impl& m = *impl_;
  if (!centre.allFinite()) {
    ++m.stats.rejected_pose;
    return Error{Errc::kInvalidArgument, "floor centre not finite"};
  }
  m.floor_c[0] = centre.x();
  m.floor_c[1] = centre.y();
  if (!m.floor_active) {
    m.problem->AddParameterBlock(m.floor_c, 2);
    m.floor_active = true;
  }
  return Ok();
}

Status SGraph::AddFloorRoom(std::uint32_t room) {
  Impl& m = *impl_;
  if (!m.floor_active || !m.ValidRoom(room)) {
    ++m.stats.rejected_missing_node;
    return Error{Errc::kNotFound, "floor-room factor without floor or room"};
  }
  RoomNode& r = m.rooms[room];
  if (r.floor_factor != kNone) m.RemoveFactor(r.floor_factor);
  r.floor_factor = kNone;
  auto slot = m.NewFactor(FactorKind::kFloorRoom, room, 0);
  if (!slot) return slot.error();
  const Eigen::Vector2d offset(m.floor_c[0] - r.c[0], m.floor_c[1] - r.c[1]);
  auto* cost = new ceres::AutoDiffCostFunction<sgraph::FloorRoomResidual, 2, 2, 2>(
      new sgraph::FloorRoomResidual{offset, 1.0 / m.config.floor_room_sigma_m});
  m.factors[static_cast<std::size_t>(*slot)].id =
      m.problem->AddResidualBlock(cost, nullptr, m.floor_c, r.c);
  ++m.stats.floor_factors;
  r.floor_factor = *slot;
  return Ok();
}

Expected<SGraphSolveReport> SGraph::Solve(SolveKind kind) {
  Impl& m = *impl_;
  SGraphSolveReport report;
  report.kind = kind;
  if (m.active_factors == 0) {
    report.usable = report.converged = true;  // nothing to solve
    return report;
  }
  // Which nodes move. Local: the newest keyframes, the planes they saw, the rooms on those
  // planes. Full: everything but the origin.
  std::int32_t window_start = m.newest;
  if (kind == SolveKind::kLocal) {
    for (std::size_t i = 1; i < m.config.local_window_keyframes; ++i) {
      const std::int32_t prev = m.keyframes[static_cast<std::size_t>(window_start)].prev;
      if (prev == kNone) break;
      window_start = prev;
    }
  } else {
    window_start = m.origin;
  }
  bool in_window = false;
  std::size_t free_keyframes = 0;
  // Walk in time order; the window is the tail of the list.
  for (std::int32_t k = m.origin; k != kNone; k = m.keyframes[static_cast<std::size_t>(k)].next) {
    if (k == window_start) in_window = true;
    const bool free = in_window && k != m.origin;
    KeyframeNode& node = m.keyframes[static_cast<std::size_t>(k)];
    m.SetFree(node.q, free);
    m.SetFree(node.t, free);
    free_keyframes += free ? 1u : 0u;
  }
  // A plane is free when its newest observer is: keyframe slots are reused, so compare stamps.
  const double window_stamp = m.keyframes[static_cast<std::size_t>(window_start)].stamp_s;
  for (std::size_t i = 0; i < m.plane_count; ++i) {
    PlaneNode& p = m.planes[i];
    if (!p.in_problem) continue;
    const std::uint32_t last = p.info.last_keyframe;
    const bool free =
        kind == SolveKind::kFull || (last < m.keyframe_high_water && m.keyframes[last].active &&
                                     m.keyframes[last].stamp_s >= window_stamp);
    m.SetFree(p.n, free);
    m.SetFree(p.d, free);
  }
  for (std::size_t i = 0; i < m.room_count; ++i) {
    RoomNode& r = m.rooms[i];
    if (!r.in_problem) continue;
    bool free = kind == SolveKind::kFull;
    const int walls = r.info.shape == RoomShape::kFourWall ? 4 : 2;
    for (int w = 0; w < walls && !free; ++w) {
      const auto& plane =
          m.planes[static_cast<std::size_t>(r.info.walls[static_cast<std::size_t>(w)])];
      free = !m.problem->IsParameterBlockConstant(const_cast<double*>(plane.d));
    }
    m.SetFree(r.c, free);
  }
  if (m.floor_active) m.SetFree(m.floor_c, kind == SolveKind::kFull);

  ceres::Solver::Options options;
  options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  options.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  options.max_num_iterations =
      kind == SolveKind::kLocal ? m.config.local_max_iterations : m.config.full_max_iterations;
  options.max_solver_time_in_seconds =
      kind == SolveKind::kLocal ? m.config.local_max_seconds : m.config.full_max_seconds;
  options.num_threads = 1;  // core owns no threads
  options.function_tolerance = 1e-7;
  options.logging_type = ceres::SILENT;
  m.Snapshot(false);
  ceres::Solver::Summary summary;
  ceres::Solve(options, m.problem.get(), &summary);
  ++m.stats.solves;
  report.iterations = static_cast<int>(summary.iterations.size());
  report.initial_cost = summary.initial_cost;
  report.final_cost = summary.final_cost;
  report.seconds = summary.total_time_in_seconds;
  report.free_keyframes = free_keyframes;
  report.converged = summary.termination_type == ceres::CONVERGENCE;
  report.usable = (summary.termination_type == ceres::CONVERGENCE ||
                   summary.termination_type == ceres::NO_CONVERGENCE ||
                   summary.termination_type == ceres::USER_SUCCESS) &&
                  std::isfinite(summary.final_cost) && m.StateFinite();
  if (!report.converged) ++m.stats.solves_not_converged;
  if (!report.usable) {
    m.Snapshot(true);  // a failed solve leaves the graph as it was
    ++m.stats.solves_undone;
  }
  return report;
}

std::size_t SGraph::keyframe_slots() const { return impl_->keyframe_high_water; }
bool SGraph::keyframe_active(std::uint32_t id) const { return impl_->ValidKeyframe(id); }
Eigen::Isometry3d SGraph::keyframe_pose(std::uint32_t id) const {
  return id < impl_->keyframe_high_water ? impl_->Pose(id) : Eigen::Isometry3d::Identity();
}
double SGraph::keyframe_stamp(std::uint32_t id) const {
  return id < impl_->keyframe_high_water ? impl_->keyframes[id].stamp_s : 0.0;
}
std::size_t SGraph::plane_slots() const { return impl_->plane_count; }
MapPlane SGraph::plane(std::uint32_t id) const {
  if (id >= impl_->plane_count) return MapPlane{};
  const PlaneNode& p = impl_->planes[id];
  MapPlane out = p.info;
  out.normal = Eigen::Vector3d(p.n[0], p.n[1], p.n[2]).normalized();
  out.d = p.d[0];
  return out;
}
Status SGraph::PlaneMarginals(std::span<const std::uint32_t> ids,
                              std::span<Eigen::Matrix3d> covariances) const {
  Impl& m = *impl_;
  if (covariances.size() < ids.size())
    return Error{Errc::kCapacityExceeded, "plane marginals: output shorter than the plane list"};
  // Ceres recovers the marginals from one factorisation of the whole problem (SuiteSparse QR);
  // it allocates, which is why this runs at the distillation cadence, not per keyframe.
  std::vector<std::pair<const double*, const double*>> blocks;
  blocks.reserve(ids.size() * 3);
  for (std::uint32_t id : ids) {
    if (id >= m.plane_count || !m.planes[id].in_problem)
      return Error{Errc::kNotFound, "plane marginals: plane not in the optimisation"};
    const PlaneNode& p = m.planes[id];
    blocks.emplace_back(p.n, p.n);
    blocks.emplace_back(p.n, p.d);
    blocks.emplace_back(p.d, p.d);
  }
  if (ids.empty()) return Ok();
  // A local solve leaves the nodes outside its window constant, and a constant block has no
  // covariance: free everything but the origin, as a full solve does (every Solve sets the
  // flags it needs again).
  for (std::int32_t k = m.origin; k != kNone; k = m.keyframes[static_cast<std::size_t>(k)].next) {
    KeyframeNode& node = m.keyframes[static_cast<std::size_t>(k)];
    m.SetFree(node.q, k != m.origin);
    m.SetFree(node.t, k != m.origin);
  }
  for (std::size_t i = 0; i < m.plane_count; ++i) {
    if (!m.planes[i].in_problem) continue;
    m.SetFree(m.planes[i].n, true);
    m.SetFree(m.planes[i].d, true);
  }
  for (std::size_t i = 0; i < m.room_count; ++i) {
    if (m.rooms[i].in_problem) m.SetFree(m.rooms[i].c, true);
  }
  if (m.floor_active) m.SetFree(m.floor_c, true);
  ceres::Covariance::Options options;
  options.algorithm_type = ceres::SPARSE_QR;
  options.num_threads = 1;
  ceres::Covariance covariance(options);
  if (!covariance.Compute(blocks, m.problem.get()))
    return Error{Errc::kDegenerate, "plane marginals: the problem is rank deficient"};
  for (std::size_t i = 0; i < ids.size(); ++i) {
    const PlaneNode& p = m.planes[ids[i]];
    // Ambient blocks (normal in R^3, offset), projected on the plane's own (u, v) basis.
    Eigen::Matrix<double, 3, 3, Eigen::RowMajor> nn;
    Eigen::Vector3d nd;
    double dd = 0;
    if (!covariance.GetCovarianceBlock(p.n, p.n, nn.data()) ||
        !covariance.GetCovarianceBlock(p.n, p.d, nd.data()) ||
        !covariance.GetCovarianceBlock(p.d, p.d, &dd)) {
      return Error{Errc::kDegenerate, "plane marginals: block not available"};
    }
    Eigen::Matrix4d full;
    full.topLeftCorner<3, 3>() = nn;
    full.topRightCorner<3, 1>() = nd;
    full.bottomLeftCorner<1, 3>() = nd.transpose();
    full(3, 3) = dd;
    Eigen::Matrix<double, 3, 4> B = Eigen::Matrix<double, 3, 4>::Zero();
    B.block<1, 3>(0, 0) = p.info.basis_u.transpose();
    B.block<1, 3>(1, 0) = p.info.basis_v.transpose();
    B(2, 3) = 1.0;
    covariances[i] = B * full * B.transpose();
    if (!covariances[i].allFinite()) return Error{Errc::kDegenerate, "plane marginals: not finite"};
  }
  return Ok();
}

std::size_t SGraph::room_slots() const { return impl_->room_count; }
MapRoom SGraph::room(std::uint32_t id) const {
  if (id >= impl_->room_count) return MapRoom{};
  MapRoom out = impl_->rooms[id].info;
  out.centre = Eigen::Vector2d(impl_->rooms[id].c[0], impl_->rooms[id].c[1]);
  return out;
}
bool SGraph::has_floor() const { return impl_->floor_active; }
Eigen::Vector2d SGraph::floor_centre() const { return {impl_->floor_c[0], impl_->floor_c[1]}; }

std::size_t SGraph::RecentKeyframes(std::span<std::uint32_t> out) const {
  const Impl& m = *impl_;
  std::size_t count = 0;
  std::int32_t k = m.newest;
  while (k != kNone && count < out.size()) {
    ++count;
    k = m.keyframes[static_cast<std::size_t>(k)].prev;
  }
  // Fill oldest first.
  k = m.newest;
  for (std::size_t i = count; i-- > 0;) {
    out[i] = static_cast<std::uint32_t>(k);
    k = m.keyframes[static_cast<std::size_t>(k)].prev;
  }
  return count;
}

SGraphStats SGraph::stats() const {
  SGraphStats s = impl_->stats;
  s.keyframes = impl_->active_keyframes;
  s.planes = impl_->plane_count;
  s.rooms = 0;
  for (std::size_t i = 0; i < impl_->room_count; ++i)
    s.rooms += impl_->rooms[i].info.active ? 1u : 0u;
  s.floors = impl_->floor_active ? 1u : 0u;
  s.factors = impl_->active_factors;
  return s;
}

const SGraphConfig& SGraph::config() const { return impl_->config; }

}  // namespace msgraphs::core
