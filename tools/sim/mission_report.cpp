// SPDX-License-Identifier: MIT
#include "mission_report.hpp"

#include <cstdio>
#include <fstream>
#include <iomanip>
#include <numbers>

namespace msgraphs::sim {
namespace {
constexpr double kRadToDeg = 180.0 / std::numbers::pi;
}  // namespace

bool WriteMissionTxt(const World& world,
                     const Mission& mission,
                     const MissionSettings& settings,
                     const std::vector<RobotReport>& robots,
                     const std::string& path) {
  std::ofstream out(path);
  if (!out) return false;
  out << std::setprecision(9);
  const MissionConfig& c = mission.config;
  out << "msgraphs-mission 1\nworld " << world.name << "\nseed " << c.seed << "\nduration_s "
      << c.duration_s << "\nrobots " << c.robots << "\nshared_rooms";
  for (const auto& r : mission.shared_rooms) out << " " << r;
  out << "\nvisit_kinds peek " << c.visit_kinds.peek << " partial " << c.visit_kinds.partial
      << " full " << c.visit_kinds.full << "\nstart_delays " << settings.start_delays << "\ngait "
      << (c.gait.enabled ? "on" : "off") << "\nslip_events " << (settings.slip ? "on" : "off")
      << "\npeople " << mission.people.size() << "\ntruth_rate_hz " << settings.truth_rate_hz
      << "\n";
  for (const RobotReport& r : robots) {
    const RobotPlan& p = *r.plan;
    const OdometrySimStats& o = r.odometry;
    out << "robot " << p.id << " start_room " << p.start_room << " start_delay_s "
        << p.start_delay_s << " unix_offset_s " << std::to_string(r.clocks.unix_offset_s)
        << " scale_error " << o.scale_error << " yaw_drift_rad_per_m " << o.yaw_drift_rad_per_m
        << " dropped_samples " << o.dropped << " path_m " << o.path_length_m << " gait_bob_m "
        << p.gait.bob_m << " gait_roll_deg " << p.gait.roll_rad * kRadToDeg << " gait_pitch_deg "
        << p.gait.pitch_rad * kRadToDeg << " slip_per_100m " << o.slip_per_100m << " slips "
        << o.slips.size() << " person_returns " << r.lidar.person_returns << " rooms";
    for (const auto& room : p.rooms_visited) out << " " << room;
    out << "\n";
  }
  for (const RobotReport& r : robots) {
    for (const Visit& v : r.plan->visits) {
      out << "visit robot " << r.plan->id << " room " << v.room << " kind " << ToString(v.kind)
          << " start_s " << v.start_s << " end_s " << v.end_s << " points " << v.points << "\n";
    }
  }
  for (const RobotReport& r : robots) {
    for (const SlipEvent& s : r.odometry.slips) {
      out << "slip robot " << r.plan->id << " start_s " << s.start_s << " duration_s "
          << s.duration_s << " kind " << s.kind << " scale " << s.scale << " yaw_deg "
          << s.yaw_rad * kRadToDeg << " true_m " << s.true_m << "\n";
    }
  }
  for (const Person& p : mission.people) {
    out << "person " << p.id << " start_room " << p.start_room << " radius_m " << p.radius_m
        << " height_m " << p.height_m << " speed_mps " << p.speed_mps << " knots " << p.knots.size()
        << "\n";
  }
  return static_cast<bool>(out);
}

bool WritePeopleCsv(const Mission& mission, const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) return false;
  // Straight walks between knots at constant speed (or standing where a knot repeats).
  std::fprintf(f, "person,t_s,x,y,radius_m,height_m\n");
  for (const Person& p : mission.people) {
    for (const PersonKnot& k : p.knots) {
      std::fprintf(f, "%d,%.4f,%.4f,%.4f,%.3f,%.3f\n", p.id, k.t_s, k.position.x(), k.position.y(),
                   p.radius_m, p.height_m);
    }
  }
  return std::fclose(f) == 0;
}

}  // namespace msgraphs::sim
