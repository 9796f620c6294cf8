// SPDX-License-Identifier: MIT
#include "msgraphs/core/collab/distiller.hpp"

#include <Eigen/Cholesky>
#include <cmath>

namespace msgraphs::core {

Status DistillerConfig::Validate() const {
  if (min_wall_observations < 1 || !(resend_distance_m > 0) || !(resend_angle_rad > 0) ||
      !(resend_covariance_ratio > 0) || max_walls < 1 || max_rooms < 1) {
    return Error{Errc::kInvalidConfig, "distiller: thresholds and capacities must be positive"};
  }
  return Ok();
}

Distiller::~Distiller() { static_cast<void>(job_.Release()); }

Status Distiller::Init(std::uint16_t robot,
                       const SGraphConfig& graph,
                       const DistillerConfig& config) {
  if (auto s = config.Validate(); !s) return s;
  static_cast<void>(job_.Release());  // a job from a previous Init
  if (config.marginal_covariances) {
    if (auto s = job_.Init(graph); !s) return s;
  }
  config_ = config;
  out_.Init(config.max_walls, config.max_rooms);
  out_.robot = robot;
  wall_slot_.assign(graph.max_planes, -1);
  room_slot_.assign(graph.max_rooms, -1);
  needed_.assign(graph.max_planes, 0);
  eligible_.Init(graph.max_planes);
  marginal_.assign(graph.max_planes, Eigen::Matrix3d::Zero());
  now_.assign(graph.max_planes, Eigen::Matrix3d::Zero());
  marginal_known_.assign(graph.max_planes, 0);
  own_plane_.assign(graph.max_planes, Eigen::Vector4d::Zero());
  own_room_.assign(graph.max_rooms, Eigen::Vector2d::Zero());
  own_plane_known_.assign(graph.max_planes, 0);
  own_room_known_.assign(graph.max_rooms, 0);
  own_floor_known_ = false;
  marginals_failed_ = false;
  job_revision_.reset();
  stats_ = {};
  updated_once_ = false;
  return Ok();
}

bool Distiller::CollectMarginals() {
  if (!job_.pending()) return false;
  if (!job_.done()) {
    if (!job_.TryClaim()) {
      // A runner has it: never wait on it here; a later Update takes it (and begins no other
      // meanwhile).
      ++stats_.marginals_not_ready;
      return false;
    }
    job_.Run();  // nobody took it: the same result, on this thread
    ++stats_.marginals_run_at_update;
  }
  TakeJob();
  return true;
}

void Distiller::TakeJob() {
  if (!job_.own_solve_usable()) {
    // Nothing from it: the estimates and covariances of the newest usable job stand.
    ++stats_.own_solve_failures;
    static_cast<void>(job_.Release());
    return;
  }
  if (job_.own_solved()) {
    ++stats_.own_evidence_jobs;
    if (!job_.own_solve_converged()) ++stats_.own_solve_unconverged;
  }
  StoreMarginals(job_.marginal_planes(), job_.plane_marginals());
  std::fill(own_plane_known_.begin(), own_plane_known_.end(), 0);
  std::fill(own_room_known_.begin(), own_room_known_.end(), 0);
  for (std::uint32_t id : job_.marginal_planes()) {
    Eigen::Vector3d n;
    double d = 0;
    if (id < own_plane_.size() && job_.PlaneEstimate(id, n, d)) {
      own_plane_[id] << n, d;
      own_plane_known_[id] = 1;
    }
  }
  for (std::uint32_t r = 0; r < own_room_.size(); ++r)
    own_room_known_[r] = job_.RoomCentre(r, own_room_[r]) ? 1 : 0;
  own_floor_known_ = job_.FloorCentre(own_floor_);
  static_cast<void>(job_.Release());
}

bool Distiller::WallEstimate(const SGraph& graph, std::uint32_t id, bool own, Eigen::Vector3d& n,
                             double& d) const {
  if (own) {
    if (id >= own_plane_known_.size() || own_plane_known_[id] == 0) return false;
    n = own_plane_[id].head<3>();
    d = own_plane_[id][3];
    return true;
  }
  const MapPlane p = graph.plane(id);
  n = p.normal;
  d = p.d;
  return true;
}

void Distiller::StoreMarginals(std::span<const std::uint32_t> ids,
                               std::span<const Eigen::Matrix3d> covariances) {
  marginals_failed_ = covariances.size() != ids.size();
  if (marginals_failed_) {
    ++stats_.marginal_failures;
    return;
  }
  ++stats_.marginal_updates;
  for (std::size_t i = 0; i < ids.size(); ++i) {
    if (ids[i] >= marginal_.size()) continue;
    marginal_[ids[i]] = covariances[i];
    marginal_known_[ids[i]] = 1;
  }
}

void Distiller::FindEligible(const SGraph& graph) {
  // Walls the rooms stand on are always shared.
  std::fill(needed_.begin(), needed_.end(), 0);
  for (std::uint32_t r = 0; r < graph.room_slots(); ++r) {
    const MapRoom room = graph.room(r);
    if (!room.active) continue;
    for (std::int32_t w : room.walls) {
      if (w >= 0 && static_cast<std::size_t>(w) < needed_.size())
        needed_[static_cast<std::size_t>(w)] = 1;
    }
  }
  eligible_.clear();
  unobserved_ = 0;
  for (std::uint32_t id = 0; id < graph.plane_slots() && id < wall_slot_.size(); ++id) {
    const MapPlane p = graph.plane(id);
    if (!p.active || p.plane_class != PlaneClass::kWall) continue;
    if (p.observations < config_.min_wall_observations && needed_[id] == 0) continue;
    if (p.live_observations == 0) {
      ++unobserved_;  // counted by Update (BeginMarginals looks too)
      continue;
    }
    Eigen::LLT<Eigen::Matrix3d> llt(p.information);
    if (llt.info() != Eigen::Success) continue;  // not yet constrained in every direction
    eligible_.push_back(id);
  }
}

bool Distiller::BeginMarginals(const SGraph& graph) {
  if (!config_.marginal_covariances || job_.pending()) return false;
  const std::uint64_t revision = graph.stats().revision;
  if (job_revision_ == revision) return false;  // they are known
  FindEligible(graph);
  if (eligible_.empty()) return false;
  if (!graph.BeginPlaneMarginals(job_, eligible_.span(), PlaneEvidence::kOwn)) {
    marginals_failed_ = true;  // the conditional covariances stand in until one succeeds
    ++stats_.marginal_failures;
    return false;
  }
  job_revision_ = revision;
  ++stats_.marginals_begun;
  return true;
}

void Distiller::MarginalsNow(const SGraph& graph) {
  // The graph's marginals job run at once (SGraph::PlaneMarginals): the same covariances the
  // background path computes for the same graph, whatever the heap did, so the evaluation's
  // lock-step missions are bit for bit from one run to the next.
  // A failure passes no covariances: StoreMarginals counts it (eligible_ is never empty here).
  const bool ok = static_cast<bool>(graph.PlaneMarginals(eligible_.span(), now_));
  StoreMarginals(eligible_.span(),
                 ok ? std::span<const Eigen::Matrix3d>(now_.data(), eligible_.size())
                    : std::span<const Eigen::Matrix3d>());
}

void Distiller::ForgetOwnEstimates() {
  std::fill(own_plane_known_.begin(), own_plane_known_.end(), 0);
  std::fill(own_room_known_.begin(), own_room_known_.end(), 0);
  own_floor_known_ = false;
}

void Distiller::OwnMarginalsNow(const SGraph& graph) {
  static_cast<void>(job_.Release());
  if (!graph.BeginPlaneMarginals(job_, eligible_.span(), PlaneEvidence::kOwn)) {
    // Older own estimates are not the graph's now: nothing goes out until a job succeeds.
    ForgetOwnEstimates();
    marginals_failed_ = true;
    ++stats_.marginal_failures;
    return;
  }
  job_.Complete();  // nobody else has it: runs here
  TakeJob();
}

bool Distiller::Update(const SGraph& graph, const PlaneMapper& planes, MarginalsTiming timing) {
  const bool background = config_.marginal_covariances && timing == MarginalsTiming::kBackground;
  // The marginals begun at the last Update (normally run by another thread meanwhile). A kNow
  // Update computes its own: an older job is released, not run.
  bool fresh = false;
  if (background)
    fresh = CollectMarginals();
  else
    static_cast<void>(job_.Release());
  // The S-Graph as it was at the last Update and no new marginals: the distilled graph would
  // come out the same.
  const std::uint64_t revision = graph.stats().revision;
  if (updated_once_ && revision == revision_ && !fresh) {
    ++stats_.unchanged;
    return false;
  }
  updated_once_ = true;
  revision_ = revision;
  const std::uint32_t next = out_.version + 1;
  bool changed = false;
  // Rumour-free: while the graph's estimates may hold plane priors' pull, every estimate comes
  // from the job that solved without them.
  const bool own = config_.marginal_covariances && graph.estimates_hold_priors();
  // The walls to share, then (kNow) their marginal covariances from one factorisation.
  FindEligible(graph);
  stats_.walls_unobserved += unobserved_;
  if (config_.marginal_covariances && !background) {
    if (own && eligible_.empty())
      ForgetOwnEstimates();  // no job: nothing of an older one goes out as now
    else if (own)
      OwnMarginalsNow(graph);
    else if (!eligible_.empty())
      MarginalsNow(graph);
  }
  for (std::size_t i = 0; i < eligible_.size(); ++i) {
    const std::uint32_t id = eligible_[i];
    const MapPlane p = graph.plane(id);
    Eigen::Vector3d normal = Eigen::Vector3d::UnitX();
    double offset = 0;
    // Its marginal: kNow's just computed, or kBackground's from the job BeginMarginals began.
    // Without one, after a failed computation the conditional covariance stands in; otherwise a
    // wall new since the job's copy waits for the next, never goes out overconfident.
    const bool known = config_.marginal_covariances && marginal_known_[id] != 0 &&
                       !(marginals_failed_ && !background);
    if (config_.marginal_covariances && !known && !marginals_failed_) {
      ++stats_.walls_awaiting_marginals;
      continue;
    }
    if (!WallEstimate(graph, id, own, normal, offset)) {
      ++stats_.walls_awaiting_estimates;  // not in the newest job
      continue;
    }
    Eigen::Matrix3d covariance =
        known ? marginal_[id]
              : Eigen::Matrix3d(p.information.llt().solve(Eigen::Matrix3d::Identity()));
    // Symmetric, and definite after the wire's f32 rounding: a 10 um / 10 urad floor.
    covariance = 0.5 * (covariance + covariance.transpose()).eval();
    covariance.diagonal().array() += 1e-10;
    const WallExtent& e = planes.extent(id);
    DistilledWall* w = nullptr;
    if (wall_slot_[id] < 0) {
      if (out_.walls.size() == out_.walls.capacity()) continue;  // full: the rest waits (bounded)
      out_.walls.push_back(DistilledWall{});
      wall_slot_[id] = static_cast<std::int32_t>(out_.walls.size() - 1);
      w = &out_.walls[out_.walls.size() - 1];
      w->id = id;
      w->version = 0;
    } else {
      w = &out_.walls[static_cast<std::size_t>(wall_slot_[id])];
    }
    const bool moved = w->version == 0 || std::fabs(w->d - offset) > config_.resend_distance_m ||
                       std::acos(std::min(1.0, w->normal.dot(normal))) > config_.resend_angle_rad;
    const double trace_ratio = covariance.trace() / std::max(1e-300, w->covariance.trace());
    const bool sharper =
        std::fabs(std::log(trace_ratio)) > std::log(1.0 + config_.resend_covariance_ratio);
    const bool grew = e.valid && ((w->a - e.a).norm() > 0.1 || (w->b - e.b).norm() > 0.1);
    if (moved || sharper || grew) {
      w->normal = normal;
      w->d = offset;
      w->covariance = covariance;
      if (e.valid) {
        w->a = e.a;
        w->b = e.b;
      }
      w->version = next;
      changed = true;
    }
  }
  for (std::uint32_t r = 0; r < graph.room_slots() && r < room_slot_.size(); ++r) {
    const MapRoom room = graph.room(r);
    if (!room.active) continue;
    DistilledRoom d;
    d.id = r;
    d.shape = room.shape;
    d.centre = room.centre;
    if (own) {
      if (own_room_known_[r] == 0) {
        ++stats_.rooms_awaiting_estimates;
        continue;
      }
      d.centre = own_room_[r];
    }
    bool complete = true;
    for (std::size_t i = 0; i < 4; ++i) {
      const std::int32_t w = room.walls[i];
      d.walls[i] = w;
      if (w >= 0 && (static_cast<std::size_t>(w) >= wall_slot_.size() ||
                     wall_slot_[static_cast<std::size_t>(w)] < 0)) {
        complete = false;
      }
    }
    if (!complete) continue;  // its walls are not shareable yet
    // Frame and size from the walls: x along walls[0]'s normal; sizes wall to wall.
    // Its walls' estimates (own: the job held them, their marginals came from it).
    auto line = [&](std::int32_t w, Eigen::Vector2d& n, double& off) {
      Eigen::Vector3d wall_n = Eigen::Vector3d::UnitX();
      double wall_d = 0;
      if (!WallEstimate(graph, static_cast<std::uint32_t>(w), own, wall_n, wall_d)) return false;
      const double norm = wall_n.head<2>().norm();
      n = wall_n.head<2>() / norm;
      off = wall_d / norm;
      return true;
    };
    Eigen::Vector2d n0 = Eigen::Vector2d::UnitX(), n1 = n0, n2 = n0, n3 = n0;
    double d0 = 0, d1 = 0, d2 = 0, d3 = 0;
    const bool four = room.shape == RoomShape::kFourWall;
    if (!line(room.walls[0], n0, d0) || !line(room.walls[1], n1, d1) ||
        (four && (!line(room.walls[2], n2, d2) || !line(room.walls[3], n3, d3)))) {
      ++stats_.rooms_awaiting_estimates;  // a wall without an own estimate (not in the job)
      continue;
    }
    d.yaw_rad = std::atan2(n0.y(), n0.x());
    d.size_x_m = d0 + d1;
    if (four) d.size_y_m = d2 + d3;
    DistilledRoom* slot = nullptr;
    if (room_slot_[r] < 0) {
      if (out_.rooms.size() == out_.rooms.capacity()) continue;
      out_.rooms.push_back(d);
      room_slot_[r] = static_cast<std::int32_t>(out_.rooms.size() - 1);
      slot = &out_.rooms[out_.rooms.size() - 1];
      slot->version = 0;
    } else {
      slot = &out_.rooms[static_cast<std::size_t>(room_slot_[r])];
    }
    const bool differs = slot->version == 0 || slot->shape != d.shape || slot->walls != d.walls ||
                         (slot->centre - d.centre).norm() > config_.resend_distance_m;
    if (differs) {
      *slot = d;
      slot->version = next;
      changed = true;
    }
  }
  // The floor (own: once a job held it; until then the distilled graph keeps what it had).
  const bool has_floor = graph.has_floor();
  const Eigen::Vector2d floor_centre = own ? own_floor_ : graph.floor_centre();
  if (has_floor && (!own || own_floor_known_)) {
    if (!out_.has_floor || (out_.floor_centre - floor_centre).norm() > config_.resend_distance_m) {
      out_.floor_centre = floor_centre;
      changed = true;
    }
    out_.has_floor = true;
  } else if (!has_floor) {
    out_.has_floor = false;
  }
  out_.floor_z_m = config_.floor_z_m;
  if (changed) out_.version = next;
  return changed;
}

}  // namespace msgraphs::core
