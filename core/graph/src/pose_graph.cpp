// SPDX-License-Identifier: MIT
#include "msgraphs/core/graph/pose_graph.hpp"

#include <charconv>
#include <cmath>
#include <sstream>

namespace msgraphs::core {
namespace {

constexpr std::uint32_t kMaxVertexId = 10'000'000;

// Whitespace-separated tokens of one line, parsed as numbers on demand.
class Tokens {
 public:
  explicit Tokens(std::string_view line) : rest_(line) {}
  std::string_view Next() {
    while (!rest_.empty() && (rest_.front() == ' ' || rest_.front() == '\t' || rest_.front() == '\r')) rest_.remove_prefix(1);
    std::size_t n = 0;
    while (n < rest_.size() && rest_[n] != ' ' && rest_[n] != '\t' && rest_[n] != '\r') ++n;
    const std::string_view t = rest_.substr(0, n);
    rest_.remove_prefix(n);
    return t;
  }
  bool Number(double& out) {
    const std::string_view t = Next();
    if (t.empty()) return false;
    const auto r = std::from_chars(t.data(), t.data() + t.size(), out);
    return r.ec == std::errc() && r.ptr == t.data() + t.size() && std::isfinite(out);
  }
  bool Id(std::uint32_t& out) {
    double v = 0;
    if (!Number(v) || v < 0 || v > kMaxVertexId || v != std::floor(v)) return false;
    out = static_cast<std::uint32_t>(v);
    return true;
  }

 private:
  std::string_view rest_;
};

Eigen::Isometry3d Planar(double x, double y, double theta) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(theta, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(x, y, 0);
  return T;
}

}  // namespace

Expected<PoseGraph> ParseG2o(std::string_view text, std::string* detail) {
  PoseGraph g;
  int kind = 0;  // 1 planar, 2 spatial
  std::size_t line_number = 0;
  auto fail = [&](const char* why) -> Expected<PoseGraph> {
    if (detail != nullptr) *detail = "line " + std::to_string(line_number) + ": " + why;
    return Error{Errc::kMalformed, why};
  };
  auto ensure = [&](std::uint32_t id) {
    if (id >= g.poses.size()) {
      g.poses.resize(id + 1, Eigen::Isometry3d::Identity());
      g.has_initial.resize(id + 1, false);
    }
  };
  while (!text.empty()) {
    const std::size_t nl = text.find('\n');
    const std::string_view line = text.substr(0, nl);
    text.remove_prefix(nl == std::string_view::npos ? text.size() : nl + 1);
    ++line_number;
    Tokens t(line);
    const std::string_view tag = t.Next();
    if (tag.empty() || tag.front() == '#') continue;
    const bool se2 = tag == "VERTEX_SE2" || tag == "EDGE_SE2";
    const bool se3 = tag == "VERTEX_SE3:QUAT" || tag == "EDGE_SE3:QUAT";
    if (se2 || se3) {
      const int k = se2 ? 1 : 2;
      if (kind != 0 && kind != k) {
        if (detail != nullptr) *detail = "line " + std::to_string(line_number) + ": mixed SE2 and SE3";
        return Error{Errc::kUnsupported, "g2o: mixed SE2 and SE3 elements"};
      }
      kind = k;
    }
    if (tag == "VERTEX_SE2") {
      std::uint32_t id = 0;
      double x = 0, y = 0, th = 0;
      if (!t.Id(id) || !t.Number(x) || !t.Number(y) || !t.Number(th)) return fail("g2o: bad VERTEX_SE2");
      ensure(id);
      g.poses[id] = Planar(x, y, th);
      g.has_initial[id] = true;
    } else if (tag == "VERTEX_SE3:QUAT") {
      std::uint32_t id = 0;
      double v[7];
      if (!t.Id(id)) return fail("g2o: bad VERTEX_SE3:QUAT");
      for (double& x : v) {
        if (!t.Number(x)) return fail("g2o: bad VERTEX_SE3:QUAT");
      }
      const Eigen::Quaterniond q(v[6], v[3], v[4], v[5]);
      if (std::fabs(q.norm() - 1.0) > 1e-3) return fail("g2o: vertex quaternion not unit");
      ensure(id);
      g.poses[id] = Eigen::Isometry3d::Identity();
      g.poses[id].linear() = q.normalized().toRotationMatrix();
      g.poses[id].translation() = Eigen::Vector3d(v[0], v[1], v[2]);
      g.has_initial[id] = true;
    } else if (tag == "EDGE_SE2") {
      PoseGraphEdge e;
      double x = 0, y = 0, th = 0, I[6];
      if (!t.Id(e.from) || !t.Id(e.to) || !t.Number(x) || !t.Number(y) || !t.Number(th)) return fail("g2o: bad EDGE_SE2");
      for (double& v : I) {
        if (!t.Number(v)) return fail("g2o: bad EDGE_SE2 information");
      }
      e.T_from_to = Planar(x, y, th);
      e.information = Matrix6d::Identity();
      const int idx[3] = {0, 1, 5};
      const double upper[3][3] = {{I[0], I[1], I[2]}, {I[1], I[3], I[4]}, {I[2], I[4], I[5]}};
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) e.information(idx[r], idx[c]) = upper[r][c];
      if (!e.information.allFinite()) return fail("g2o: information not finite");
      if (e.from == e.to) return fail("g2o: edge from a vertex to itself");
      double kappa = 0, tau = 0;
      SeSyncWeights(e, true, kappa, tau);
      if (!(kappa > 0) || !(tau > 0) || !std::isfinite(kappa) || !std::isfinite(tau)) return fail("g2o: unusable information");
      ensure(std::max(e.from, e.to));
      g.edges.push_back(e);
    } else if (tag == "EDGE_SE3:QUAT") {
      PoseGraphEdge e;
      double v[7], I[21];
      if (!t.Id(e.from) || !t.Id(e.to)) return fail("g2o: bad EDGE_SE3:QUAT");
      for (double& x : v) {
        if (!t.Number(x)) return fail("g2o: bad EDGE_SE3:QUAT");
      }
      for (double& x : I) {
        if (!t.Number(x)) return fail("g2o: bad EDGE_SE3:QUAT information");
      }
      const Eigen::Quaterniond q(v[6], v[3], v[4], v[5]);
      if (std::fabs(q.norm() - 1.0) > 1e-3) return fail("g2o: edge quaternion not unit");
      e.T_from_to.linear() = q.normalized().toRotationMatrix();
      e.T_from_to.translation() = Eigen::Vector3d(v[0], v[1], v[2]);
      int k = 0;
      for (int r = 0; r < 6; ++r) {
        for (int c = r; c < 6; ++c) {
          e.information(r, c) = I[k];
          e.information(c, r) = I[k];
          ++k;
        }
      }
      // Some public graphs (cubicle) carry indefinite information matrices; SE-Sync reads them
      // (it only needs the weights below), so accept them when those weights are usable.
      if (!e.information.allFinite()) return fail("g2o: information not finite");
      if (e.from == e.to) return fail("g2o: edge from a vertex to itself");
      double kappa = 0, tau = 0;
      SeSyncWeights(e, false, kappa, tau);
      if (!(kappa > 0) || !(tau > 0) || !std::isfinite(kappa) || !std::isfinite(tau)) return fail("g2o: unusable information");
      ensure(std::max(e.from, e.to));
      g.edges.push_back(e);
    } else if (tag == "FIX") {
      std::uint32_t id = 0;
      if (!t.Id(id)) return fail("g2o: bad FIX");
      g.fixed.push_back(id);
    } else {
      return fail("g2o: unknown element (only SE2 and SE3:QUAT graphs)");
    }
  }
  g.planar = kind == 1;
  if (g.poses.empty()) return fail("g2o: no vertices or edges");
  return g;
}

std::string WriteG2o(const PoseGraph& g) {
  std::ostringstream out;
  out.precision(17);
  for (std::size_t i = 0; i < g.poses.size(); ++i) {
    const Eigen::Isometry3d& T = g.poses[i];
    if (g.planar) {
      out << "VERTEX_SE2 " << i << ' ' << T.translation().x() << ' ' << T.translation().y() << ' '
          << std::atan2(T.linear()(1, 0), T.linear()(0, 0)) << '\n';
    } else {
      const Eigen::Quaterniond q(T.linear());
      out << "VERTEX_SE3:QUAT " << i << ' ' << T.translation().x() << ' ' << T.translation().y() << ' '
          << T.translation().z() << ' ' << q.x() << ' ' << q.y() << ' ' << q.z() << ' ' << q.w() << '\n';
    }
  }
  for (std::uint32_t f : g.fixed) out << "FIX " << f << '\n';
  for (const PoseGraphEdge& e : g.edges) {
    const Eigen::Isometry3d& T = e.T_from_to;
    if (g.planar) {
      const Matrix6d& I = e.information;
      out << "EDGE_SE2 " << e.from << ' ' << e.to << ' ' << T.translation().x() << ' ' << T.translation().y() << ' '
          << std::atan2(T.linear()(1, 0), T.linear()(0, 0)) << ' ' << I(0, 0) << ' ' << I(0, 1) << ' ' << I(0, 5) << ' '
          << I(1, 1) << ' ' << I(1, 5) << ' ' << I(5, 5) << '\n';
    } else {
      const Eigen::Quaterniond q(T.linear());
      out << "EDGE_SE3:QUAT " << e.from << ' ' << e.to << ' ' << T.translation().x() << ' ' << T.translation().y() << ' '
          << T.translation().z() << ' ' << q.x() << ' ' << q.y() << ' ' << q.z() << ' ' << q.w();
      for (int r = 0; r < 6; ++r)
        for (int c = r; c < 6; ++c) out << ' ' << e.information(r, c);
      out << '\n';
    }
  }
  return out.str();
}

void SeSyncWeights(const PoseGraphEdge& e, bool planar, double& kappa, double& tau) {
  if (planar) {
    const Eigen::Matrix2d Ott = e.information.topLeftCorner<2, 2>();
    tau = 2.0 / Ott.inverse().trace();
    kappa = e.information(5, 5);
  } else {
    tau = 3.0 / e.information.topLeftCorner<3, 3>().inverse().trace();
    kappa = 3.0 / (2.0 * e.information.bottomRightCorner<3, 3>().inverse().trace());
  }
}

double SeSyncObjective(const PoseGraph& g) {
  double sum = 0;
  for (const PoseGraphEdge& e : g.edges) {
    double kappa = 0, tau = 0;
    SeSyncWeights(e, g.planar, kappa, tau);
    const Eigen::Isometry3d& Ti = g.poses[e.from];
    const Eigen::Isometry3d& Tj = g.poses[e.to];
    const int d = g.planar ? 2 : 3;
    const Eigen::MatrixXd dR = (Tj.linear() - Ti.linear() * e.T_from_to.linear()).topLeftCorner(d, d);
    const Eigen::VectorXd dt =
        (Tj.translation() - Ti.translation() - Ti.linear() * e.T_from_to.translation()).head(d);
    sum += kappa * dR.squaredNorm() + tau * dt.squaredNorm();
  }
  return sum;
}

}  // namespace msgraphs::core
