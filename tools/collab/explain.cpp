// SPDX-License-Identifier: MIT
#include "explain.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>

#include "evaluation_config.hpp"
#include "msgraphs/core/collab/free_space_conflict.hpp"
#include "msgraphs/core/collab/merge_rule.hpp"
#include "msgraphs/core/collab/wall_index.hpp"

namespace msgraphs::tools::collab {
namespace {

// A map's symmetries as the session keeps them (collab_merge.cpp): its search with itself, the
// strongest that constrain both directions.
std::vector<core::Hypothesis> Symmetries(const core::WallIndex& walls, const core::DistilledGraph& g,
                                         const core::CollabSessionConfig& config) {
  core::AlignmentSearch search;
  std::vector<core::Hypothesis> out;
  if (!search.Init(config.search)) return out;
  search.Search(walls, g.rooms.span(), walls, g.rooms.span(), {}, true);
  for (const core::Hypothesis& h : search.hypotheses()) {
    if (out.size() == config.merge.max_symmetries) break;
    if (h.agreement.constraint_m >= config.merge.min_rival_constraint_m) out.push_back(h);
  }
  return out;
}

void Picture(const core::FreeSpaceSummary& f, const core::WallIndex& other, const core::FreeSpaceSummary& other_free,
             const core::PlanarTransform& T, double clearance_m, const std::string& path) {
  if (f.empty()) return;
  const int w = f.width(), h = f.height();
  std::vector<unsigned char> image(static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * 3);
  auto pixel = [&](int x, int y) { return &image[(static_cast<std::size_t>(h - 1 - y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x)) * 3]; };
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const core::SummaryCell s = f.state(x, y);
      const unsigned char v = s == core::SummaryCell::kFree ? 255 : s == core::SummaryCell::kOccupied ? 0 : 150;
      unsigned char* p = pixel(x, y);
      p[0] = p[1] = p[2] = v;
    }
  }
  auto draw = [&](const Eigen::Vector2d& a, const Eigen::Vector2d& b, auto&& colour) {
    const double length = (b - a).norm();
    const int steps = std::max(1, static_cast<int>(length / (0.25 * static_cast<double>(f.cell_m()))));
    for (int i = 0; i <= steps; ++i) {
      const Eigen::Vector2d q = a + (b - a) * (static_cast<double>(i) / steps);
      const int x = static_cast<int>(std::floor((q.x() - f.origin_m().x()) / static_cast<double>(f.cell_m())));
      const int y = static_cast<int>(std::floor((q.y() - f.origin_m().y()) / static_cast<double>(f.cell_m())));
      if (x < 0 || y < 0 || x >= w || y >= h) continue;
      colour(pixel(x, y), q);
    }
  };
  for (const core::AlignWall& wall : other.walls()) {
    draw(T * wall.a, T * wall.b, [&](unsigned char* p, const Eigen::Vector2d& q) {
      const bool conflict = static_cast<double>(f.clearance_m(q)) >= clearance_m;
      p[0] = 255;
      p[1] = conflict ? 0 : 140;
      p[2] = 0;
    });
  }
  for (const core::Opening& o : f.openings()) {
    draw(o.a, o.b, [](unsigned char* p, const Eigen::Vector2d&) {
      p[0] = 0;
      p[1] = 60;
      p[2] = 255;
    });
  }
  // The other robot's openings: magenta, dark red where they fall on a cell seen occupied.
  for (const core::Opening& o : other_free.openings()) {
    draw(T * o.a, T * o.b, [&](unsigned char* p, const Eigen::Vector2d& q) {
      const bool solid = f.state_at(q) == core::SummaryCell::kOccupied && !f.NearOpening(q, 0.3);
      p[0] = solid ? 140 : 255;
      p[1] = 0;
      p[2] = solid ? 0 : 255;
    });
  }
  if (std::FILE* file = std::fopen(path.c_str(), "wb")) {
    std::fprintf(file, "P6 %d %d 255\n", w, h);
    std::fwrite(image.data(), 1, image.size(), file);
    std::fclose(file);
  }
}

// Every stretch of conflict the true transform carries, in the world's frame (the truth's).
class ConflictCsv final : public core::ConflictVisitor {
 public:
  ConflictCsv(std::FILE* file, const char* direction, const Eigen::Isometry3d& T_world_y)
      : file_(file), direction_(direction), T_world_y_(T_world_y) {}
  void Counted(core::ConflictKind kind, const Eigen::Vector2d& a_y, const Eigen::Vector2d& b_y, double length_m) override {
    const Eigen::Vector3d a = T_world_y_ * Eigen::Vector3d(a_y.x(), a_y.y(), 0);
    const Eigen::Vector3d b = T_world_y_ * Eigen::Vector3d(b_y.x(), b_y.y(), 0);
    std::fprintf(file_, "%s,%s,%.2f,%.2f,%.2f,%.2f,%.2f\n", direction_,
                 kind == core::ConflictKind::kWallInFree ? "wall_in_free" : "opening_on_solid", a.x(), a.y(), b.x(),
                 b.y(), length_m);
  }

 private:
  std::FILE* file_;
  const char* direction_;
  Eigen::Isometry3d T_world_y_;
};

const char* Cause(const ViewEvaluation& v, const ViewExplanation& e, const core::MergeRuleConfig& rule) {
  if (v.merged) return v.verdict == Verdict::kWrong ? "merged wrongly" : v.verdict == Verdict::kRight ? "right" : "unchecked";
  if (v.history.unmerges() > 0) return "merged, then undone";
  if (!e.checked) return "no free space";
  if (!e.proposed) return "truth not proposed";
  if (e.truth.conflict_m() > rule.RefuteLimit(e.truth)) return "truth refuted";
  if (e.truth.agreement.agreement_m < rule.min_agreement_m || e.truth.agreement.constraint_m < rule.min_constraint_m)
    return "too little shared";
  if (e.truth.conflict_m() > rule.AcceptLimit(e.truth)) return "truth conflicted";
  if (e.decision.verdict == core::MergeVerdict::kAmbiguous) return "ambiguous";
  if (e.decision.verdict == core::MergeVerdict::kTruncated) return "search truncated";
  if (e.decision.verdict == core::MergeVerdict::kSelfContradicted) return "a map contradicts itself";
  return "undecided at the end";
}

}  // namespace

std::vector<ViewExplanation> ExplainViews(const Mission& mission, const Evaluation& evaluation,
                                          const std::string& pictures_dir) {
  std::vector<ViewExplanation> out;
  if (mission.keyframes) return out;
  if (!pictures_dir.empty()) std::filesystem::create_directories(pictures_dir);
  const std::size_t n = mission.robots.size();
  std::vector<core::WallIndex> own(n);
  std::vector<std::vector<core::Hypothesis>> symmetries(n);
  for (std::size_t i = 0; i < n; ++i) {
    const core::CollabSession& s = mission.robots[i]->session;
    static_cast<void>(own[i].Init(s.config().distiller.max_walls));
    own[i].Build(s.distilled().walls.span(), s.config().search.min_wall_length_m);
    symmetries[i] = Symmetries(own[i], s.distilled(), s.config());
    // Rule 6's evidence: the robot's walls in its own free space, stretch by stretch.
    if (pictures_dir.empty() || i >= evaluation.robots.size()) continue;
    const std::string path = pictures_dir + "/robot" + std::to_string(i + 1) + "_self_conflicts.csv";
    if (std::FILE* file = std::fopen(path.c_str(), "w")) {
      std::fprintf(file, "# the robot's walls in its own free space (rule 6), stretch by stretch, world frame (truth)\n"
                         "direction,kind,ax_m,ay_m,bx_m,by_m,length_m\n");
      ConflictCsv self(file, "self", evaluation.robots[i].own.T_truth_estimate);
      static_cast<void>(core::ConflictOf(own[i], s.free_space(), core::PlanarTransform{}, own[i], s.free_space(),
                                         s.config().merge.conflict, &self, false));
      std::fclose(file);
    }
  }
  core::AlignmentSearch search;
  for (const ViewEvaluation& v : evaluation.views) {
    ViewExplanation e;
    e.viewer = v.viewer;
    e.robot = v.robot;
    const auto a = static_cast<std::size_t>(v.viewer - 1), b = static_cast<std::size_t>(v.robot - 1);
    const core::CollabSession& sa = mission.robots[a]->session;
    const core::CollabSession& sb = mission.robots[b]->session;
    const core::CollabSessionConfig& config = sa.config();
    if (!search.Init(config.search)) break;
    const core::DistilledGraph* peer = sa.peer_graph(static_cast<std::uint16_t>(v.robot));
    const RobotEvaluation& ra = evaluation.robots[a];
    const RobotEvaluation& rb = evaluation.robots[b];
    const bool truth_known = ra.own.ok && rb.own.ok;
    if (peer != nullptr && truth_known && !sa.free_space().empty() && !sb.free_space().empty()) {
      e.checked = true;
      core::WallIndex walls_b;
      static_cast<void>(walls_b.Init(config.distiller.max_walls));
      walls_b.Build(peer->walls.span(), config.search.min_wall_length_m);
      std::vector<core::RoomMatch> matches(64);
      matches.resize(sa.AllMatches(static_cast<std::uint16_t>(v.robot), matches));
      std::vector<core::PlanarTransform> seeds;
      for (const core::RoomMatch& m : matches) seeds.push_back(core::PlanarTransform::FromIsometry(m.T_a_b));
      search.Search(own[a], sa.distilled().rooms.span(), walls_b, peer->rooms.span(), seeds, false);
      core::MergeInputs in;
      in.walls_a = &own[a];
      in.walls_b = &walls_b;
      in.free_a = &sa.free_space();
      in.free_b = &sb.free_space();
      in.hypotheses = search.hypotheses();
      in.truncated = search.truncated();
      in.channels = search.channels();
      in.sym_a = symmetries[a];
      in.sym_b = symmetries[b];
      // B's symmetries as A sees them: from the walls A holds of B.
      const std::vector<core::Hypothesis> sym_b = Symmetries(walls_b, *peer, config);
      in.sym_b = sym_b;
      const core::PlanarTransform T_truth = core::PlanarTransform::FromIsometry(
          ra.own.T_truth_estimate.inverse() * rb.own.T_truth_estimate);
      const core::PlanarTransform current = core::PlanarTransform::FromIsometry(sa.T_self_robot(static_cast<std::uint16_t>(v.robot)));
      e.decision = core::DecideMerge(in, search, config.merge, v.merged ? &current : nullptr);
      e.hypotheses = search.hypotheses().size();
      for (std::size_t k = 0; k < search.hypotheses().size(); ++k) {
        if (core::SameTransform(search.hypotheses()[k].T_a_b, T_truth, 0.5, 2.0 * std::numbers::pi / 180.0)) {
          e.proposed = true;
          e.rank = k;
          break;
        }
      }
      e.truth = search.Evaluate(own[a], walls_b, T_truth);
      core::MeasureConflict(e.truth, in, config.merge.conflict);
      if (e.decision.has_leader) e.leader_truth_distance_m = (e.decision.leader.T_a_b.t_m - T_truth.t_m).norm();
      if (v.merged) {
        const auto id = static_cast<std::uint16_t>(v.robot);
        e.merge_truth_distance_m = (core::PlanarTransform::FromIsometry(sa.T_self_robot_merge(id)).t_m - T_truth.t_m).norm();
        e.solved_truth_distance_m = (current.t_m - T_truth.t_m).norm();
      }
      if (!pictures_dir.empty()) {
        const std::string stem = pictures_dir + "/robot" + std::to_string(v.robot) + "_in_robot" + std::to_string(v.viewer);
        // Each summary with the other robot's walls laid in by `T_a_b`, both ways.
        const auto draw = [&](const core::PlanarTransform& T_a_b, const std::string& name) {
          Picture(sa.free_space(), walls_b, sb.free_space(), T_a_b, config.merge.conflict.clearance_m, name + ".ppm");
          Picture(sb.free_space(), own[a], sa.free_space(), T_a_b.inverse(), config.merge.conflict.clearance_m,
                  name + "_back.ppm");
        };
        draw(e.truth.T_a_b, stem);
        // The rule's leader when it is not the truth: what the evidence looked like under it.
        if (e.decision.has_leader && e.leader_truth_distance_m > kWrongMatch_m)
          draw(e.decision.leader.T_a_b, stem + "_leader");
        if (std::FILE* file = std::fopen((stem + "_conflicts.csv").c_str(), "w")) {
          std::fprintf(file, "# the true transform's conflict, stretch by stretch, world frame (truth)\n"
                             "direction,kind,ax_m,ay_m,bx_m,by_m,length_m\n");
          ConflictCsv b_in_a(file, "b_in_a", ra.own.T_truth_estimate);
          static_cast<void>(core::ConflictOf(walls_b, sb.free_space(), e.truth.T_a_b, own[a], sa.free_space(),
                                             config.merge.conflict, &b_in_a));
          ConflictCsv a_in_b(file, "a_in_b", rb.own.T_truth_estimate);
          static_cast<void>(core::ConflictOf(own[a], sa.free_space(), e.truth.T_a_b.inverse(), walls_b,
                                             sb.free_space(), config.merge.conflict, &a_in_b));
          std::fclose(file);
        }
      }
    }
    e.cause = Cause(v, e, config.merge);
    out.push_back(e);
  }
  return out;
}

}  // namespace msgraphs::tools::collab
