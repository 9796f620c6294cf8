// SPDX-License-Identifier: MIT
#include "people.hpp"

#include <algorithm>
#include <cmath>

#include "random.hpp"

namespace msgraphs::sim {

void Person::StateAt(double t_s, Eigen::Vector2d& position, Eigen::Vector2d& velocity) const {
  velocity.setZero();
  if (knots.empty()) {
    position.setZero();
    return;
  }
  if (t_s <= knots.front().t_s) {
    position = knots.front().position;
    return;
  }
  if (t_s >= knots.back().t_s) {
    position = knots.back().position;
    return;
  }
  const auto it = std::upper_bound(knots.begin(), knots.end(), t_s,
                                   [](double t, const PersonKnot& k) { return t < k.t_s; });
  const PersonKnot& b = *it;
  const PersonKnot& a = *(it - 1);
  const double span = b.t_s - a.t_s;
  if (span <= 0) {
    position = b.position;
    return;
  }
  velocity = (b.position - a.position) / span;
  position = a.position + velocity * (t_s - a.t_s);
}

std::vector<Person> PlanPeople(const World& world,
                               const NavGrid& grid,
                               const std::vector<int>& rooms,
                               const std::vector<std::vector<Eigen::Vector2d>>& free_cells,
                               const PeopleConfig& config,
                               double duration_s,
                               std::uint64_t seed) {
  std::vector<Person> people;
  if (rooms.empty()) return people;
  for (int id = 1; id <= config.count; ++id) {
    Random rng = Random::Stream(seed, 0x70656F70, static_cast<std::uint64_t>(id));  // "peop"
    Person person;
    person.id = id;
    person.radius_m = config.radius_m;
    person.height_m = rng.Uniform(config.height_min_m, config.height_max_m);
    person.speed_mps = rng.Uniform(config.speed_min_mps, config.speed_max_mps);
    auto pick = [&](std::size_t room) {
      const auto& cells = free_cells[room];
      return cells[static_cast<std::size_t>(rng.Index(static_cast<int>(cells.size())))];
    };
    std::size_t current = static_cast<std::size_t>(rng.Index(static_cast<int>(rooms.size())));
    person.start_room = world.rooms[static_cast<std::size_t>(rooms[current])].id;
    Eigen::Vector2d at = pick(current);
    double t = 0;
    person.knots.push_back({t, at});
    int failures = 0;
    while (t < duration_s && failures < 50) {
      std::size_t next = static_cast<std::size_t>(rng.Index(static_cast<int>(rooms.size())));
      if (next == current && rooms.size() > 1) continue;
      const Eigen::Vector2d goal = pick(next);
      const auto path = grid.Plan(at, goal, config.clearance_m);
      if (path.size() < 2) {
        ++failures;
        continue;
      }
      failures = 0;
      for (std::size_t i = 1; i < path.size(); ++i) {
        t += (path[i] - path[i - 1]).norm() / person.speed_mps;
        person.knots.push_back({t, path[i]});
      }
      t += rng.Uniform(config.pause_min_s, config.pause_max_s);
      person.knots.push_back({t, goal});
      at = goal;
      current = next;
    }
    people.push_back(std::move(person));
  }
  return people;
}

void PeopleScene::Snapshot(double t_s, Eigen::Vector2d* position, Eigen::Vector2d* velocity) const {
  for (std::size_t i = 0; i < people_->size(); ++i)
    (*people_)[i].StateAt(t_s, position[i], velocity[i]);
}

bool PeopleScene::Cast(const Eigen::Vector2d* position,
                       const Eigen::Vector2d* velocity,
                       double dt_s,
                       const Eigen::Vector3d& o,
                       const Eigen::Vector3d& d,
                       Hit& best) const {
  bool hit = false;
  const double a = d.x() * d.x() + d.y() * d.y();
  for (std::size_t i = 0; i < people_->size(); ++i) {
    const Person& person = (*people_)[i];
    const Eigen::Vector2d c = position[i] + velocity[i] * dt_s;
    const double px = o.x() - c.x(), py = o.y() - c.y();
    const double r2 = person.radius_m * person.radius_m;
    const double z0 = floor_z_m_, z1 = floor_z_m_ + person.height_m;
    if (px * px + py * py <= r2) continue;  // inside: the robot walks through (not modelled)
    if (a > 1e-12) {
      const double bq = px * d.x() + py * d.y();
      const double disc = bq * bq - a * (px * px + py * py - r2);
      if (disc >= 0) {
        const double s = (-bq - std::sqrt(disc)) / a;
        const double z = o.z() + s * d.z();
        if (s > 1e-6 && s < best.range_m && z >= z0 && z <= z1) {
          best = {s,
                  Eigen::Vector3d(px + s * d.x(), py + s * d.y(), 0).normalized(),
                  Material::kFabric,
                  -1,
                  0,
                  static_cast<std::int32_t>(i)};
          hit = true;
          continue;
        }
      }
    }
    if (d.z() < -1e-12 && o.z() > z1) {  // the head, from above
      const double s = (z1 - o.z()) / d.z();
      const double x = px + s * d.x(), y = py + s * d.y();
      if (s > 1e-6 && s < best.range_m && x * x + y * y <= r2) {
        best = {s, Eigen::Vector3d(0, 0, 1),    Material::kFabric, -1,
                0, static_cast<std::int32_t>(i)};
        hit = true;
      }
    }
  }
  return hit;
}

}  // namespace msgraphs::sim
