// SPDX-License-Identifier: MIT
// msgraphs_collab: a multi-robot mission (simulator recordings) through the whole Multi S-Graphs
// pipeline in one process, deterministically: every robot's local S-Graph in lock-step by
// mission time; every `--exchange-every-s` each robot's core::CollabSession (the same class the
// onboard node runs) publishes what changed, and the messages cross an in-process radio (the
// real wire encodings, decoded by every peer, bytes counted per type and link). Receivers match
// rooms by Scan Context, request room clouds for fine alignment (modes with "fine"), keep the
// largest mutually consistent set of matches per robot pair, and solve their collaborative graph.
//
// At the end it reports, from robot 1's point of view: which robots were merged, the ATE of the
// aggregated trajectory (every merged robot's keyframes in robot 1's frame through the
// estimated origins, one SE(3) alignment to the ground truth), room matches accepted and
// rejected (and how many accepted ones are wrong against the truth), and data exchanged per
// message type. --mode keyframes runs the keyframe-level baseline instead of rooms.
//
//   msgraphs_collab --run DIR [--mode rooms|rooms-fine|rooms-walls|rooms-walls-fine|keyframes]
//                   [--cloud f32|q16|q8] [--cloud-step 0.01] [--feedback on|off]
//                   [--exchange-every-s 10] [--delay-s ROBOT=SECONDS]... [--hypotheses walls|count]
//                   [--out DIR] [--markdown]
//
// --feedback on (the default) gives each robot's local S-Graph the other robots' measurements of
// its matched walls, through the merged origins (CollabSession::PlanePriors).
//
// --out DIR writes robotN_in_robot1.tum (every merged robot's keyframes in robot 1's frame) and
// bytes.csv (cumulative bytes per message type after each exchange, all links together).
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "msgraphs/core/collab/collab_session.hpp"
#include "msgraphs/core/collab/distilled_codec.hpp"
#include "msgraphs/core/collab/room_descriptor.hpp"
#include "msgraphs/core/collab/room_matcher.hpp"
#include "msgraphs/core/collab/room_messages.hpp"
#include "msgraphs/core/graph/collaborative_graph.hpp"
#include "msgraphs/core/slam/local_mapper.hpp"
#include "msgraphs/drivers/can_odometry/candump_file.hpp"
#include "msgraphs/drivers/can_odometry/odometry_stream.hpp"
#include "msgraphs/drivers/velodyne/recorded_scans.hpp"
#include "msgraphs/tools/tum.hpp"

namespace {

using namespace msgraphs;
namespace fs = std::filesystem;

enum MessageType {
  kGraph,
  kDescriptor,
  kCloudRequest,
  kCloud,
  kFreeSpace,
  kKeyframeDescriptor,
  kKeyframeCloud,
  kMessageTypes
};
const char* kTypeNames[kMessageTypes] = {"distilled graph",      "room descriptors",
                                         "room cloud requests",  "room clouds", "free space",
                                         "keyframe descriptors", "keyframe clouds"};
constexpr std::size_t kKeyframePoseBytes = 28;  // a keyframe's pose beside its descriptor (7 x f32)
constexpr float kKeyframeScThreshold = 0.25f;   // keyframe candidates (tighter: many more of them)

struct Robot {
  int index = 0;  // 0-based; robot ids on the wire are index + 1
  std::uint16_t id() const { return static_cast<std::uint16_t>(index + 1); }
  std::unique_ptr<drivers::velodyne::RecordedScans> scans;
  std::optional<drivers::can_odometry::CandumpFileReader> candump;
  drivers::can_odometry::OdometryStream odometry =
      drivers::can_odometry::OdometryStream::Create({}).value();
  bool odometry_done = false, scans_done = false;
  const drivers::velodyne::Scan* pending = nullptr;
  double first_stamp = -1;
  double delay_s = 0;  // --delay-s: this robot's mission starts this much later
  core::LocalMapper mapper;
  core::CollabSession session;
  // Baseline: keyframe descriptors (own), and those received with the sender's pose at the time;
  // its matches, consistent sets and collaborative graph (origin measurements only).
  std::uint32_t keyframes_sent = 0;
  std::map<std::uint32_t, core::ScanContext> own_keyframes;
  std::map<std::pair<int, std::uint32_t>, std::pair<core::ScanContext, Eigen::Isometry3d>>
      peer_keyframes;
  std::set<std::pair<int, std::uint32_t>> tried_keyframes;
  std::map<int, std::vector<core::RoomMatch>> matches;
  std::map<int, std::vector<std::uint32_t>> consistent;
  core::CollaborativeGraph collab;
  std::uint64_t proposals = 0, rejected_fine = 0, rejected_consistency = 0;
  std::vector<tools::StampedPose> truth;
};

double Now(const Robot& r) {
  return r.pending == nullptr
             ? 1e300
             : r.pending->end_time.seconds_since_epoch() - r.first_stamp + r.delay_s;
}

void Advance(Robot& r) {
  r.pending = r.scans->Next();
  if (r.pending == nullptr)
    r.scans_done = true;
  else if (r.first_stamp < 0)
    r.first_stamp = r.pending->end_time.seconds_since_epoch();
}

void FeedOdometry(Robot& r, double until) {
  drivers::can_odometry::CandumpLine line;
  while (!r.odometry_done && r.mapper.odometry().newest_stamp() < until) {
    auto next = r.candump->Next(line);
    if (!next || !*next) {
      r.odometry_done = true;
      break;
    }
    if (!r.odometry.Add(line.frame, line.stamp)) continue;
    const auto& p = r.odometry.pose();
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() =
        Eigen::Quaterniond(p.T_odom_base.qw, p.T_odom_base.qx, p.T_odom_base.qy, p.T_odom_base.qz)
            .normalized()
            .toRotationMatrix();
    T.translation() << p.T_odom_base.x_m, p.T_odom_base.y_m, p.T_odom_base.z_m;
    static_cast<void>(r.mapper.AddOdometry(p.stamp.seconds_since_epoch(), T));
  }
}

void ProcessScan(Robot& r) {
  static std::vector<Eigen::Vector3f> points;
  static std::vector<float> times;
  points.clear();
  times.clear();
  for (const auto& p : r.pending->points) {
    points.emplace_back(p.x_m, p.y_m, p.z_m);
    times.push_back(static_cast<float>(p.time_offset_ns * 1e-9));
  }
  core::LidarScanView view{points, times, r.pending->start_time.seconds_since_epoch(),
                           r.pending->end_time.seconds_since_epoch()};
  FeedOdometry(r, view.end_s + 0.05);
  static_cast<void>(r.mapper.AddScan(view));
  Advance(r);
}

struct Accounting {
  // bytes[type][from][to]
  std::map<std::tuple<int, int, int>, std::uint64_t> bytes;
  std::uint64_t malformed = 0;
  void Add(MessageType type, int from, int to, std::size_t n) { bytes[{type, from, to}] += n; }
  std::uint64_t Total(int type = -1) const {
    std::uint64_t sum = 0;
    for (const auto& [key, n] : bytes) {
      if (type < 0 || std::get<0>(key) == type) sum += n;
    }
    return sum;
  }
};

// The radio, in process: messages wait in order until Deliver hands them to their addressees
// (every peer for a broadcast), counting bytes per type and link. Queued rather than delivered
// at once so that no session is re-entered while it sends.
struct Radio final : core::CollabOutbox {
  struct Message {
    core::CollabMessageType type;
    int from;
    std::uint16_t to;
    std::vector<std::uint8_t> bytes;
  };
  std::vector<Message> queue;
  int sender = 0;
  void Send(core::CollabMessageType type,
            std::uint16_t to,
            std::span<const std::uint8_t> bytes) override {
    queue.push_back({type, sender, to, {bytes.begin(), bytes.end()}});
  }
};

struct Mission {
  std::vector<std::unique_ptr<Robot>> robots;
  bool keyframes = false;  // the baseline instead of the room-based algorithm
  bool feedback = true;    // other robots' walls back into each local S-Graph
  std::vector<core::PlanePrior> priors = std::vector<core::PlanePrior>(512);
  core::CloudEncoding cloud_encoding = core::CloudEncoding::kQuantised16;
  core::RoomMatcher matcher;  // the baseline's
  Accounting accounting;
  Radio radio;
  std::vector<std::uint8_t> buffer = std::vector<std::uint8_t>(8 << 20);
  BoundedVector<Eigen::Vector3f> decoded_cloud{200000};

  void Deliver() {
    for (std::size_t i = 0; i < radio.queue.size(); ++i) {  // Receive may queue answers
      const Radio::Message m = radio.queue[i];
      for (auto& to : robots) {
        if (to->index == m.from || (m.to != 0 && m.to != to->id())) continue;
        accounting.Add(static_cast<MessageType>(m.type), m.from, to->index, m.bytes.size());
        radio.sender = to->index;
        auto s = to->session.Receive(m.type, m.bytes, radio);
        if (!s && (s.error().code == Errc::kMalformed || s.error().code == Errc::kChecksum)) {
          if (++accounting.malformed <= 3)
            std::fprintf(stderr, "collab: robot %d rejected a message: %s\n", to->id(),
                         s.error().detail);
        }
      }
    }
    radio.queue.clear();
  }

  double now_s = 0;  // mission time of the exchange
  void Exchange() {
    if (keyframes) {
      for (auto& r : robots) ExchangeKeyframes(*r);
      for (auto& r : robots) MatchKeyframes(*r);
      return;
    }
    for (auto& r : robots) {
      radio.sender = r->index;
      static_cast<void>(r->session.Publish(r->mapper, radio));
    }
    Deliver();
    // Match, deliver the cloud requests and their answers, and align what arrived.
    for (int round = 0; round < 2; ++round) {
      for (auto& r : robots) {
        radio.sender = r->index;
        r->session.Match(radio, now_s);
      }
      Deliver();
    }
    if (!feedback) return;
    for (auto& r : robots) {
      const std::size_t n = r->session.PlanePriors(priors);
      static_cast<void>(r->mapper.SetPlanePriors(std::span(priors.data(), n)));
    }
  }

  void ExchangeKeyframes(Robot& from) {
    const core::SGraph& g = from.mapper.graph();
    const core::ScanContextConfig sc_config{20, 60, 20.0f, 0.5f};  // heights above the floor
    for (std::uint32_t k = from.keyframes_sent; k < g.keyframe_slots(); ++k) {
      const auto cloud = from.mapper.keyframe_cloud(k);
      if (cloud.empty()) continue;
      core::ScanContext& sc = from.own_keyframes[k];
      if (!sc.Build(cloud, sc_config)) continue;
      auto n = core::EncodeRoomDescriptor({from.id(), k, 0}, sc, buffer);
      if (!n) continue;
      for (auto& to : robots) {
        if (to.get() == &from) continue;
        accounting.Add(kKeyframeDescriptor, from.index, to->index, *n + kKeyframePoseBytes);
        core::ScanContext received;
        if (!core::DecodeRoomDescriptor(std::span(buffer.data(), *n), received)) {
          ++accounting.malformed;
          continue;
        }
        to->peer_keyframes[{from.index, k}] = {received, g.keyframe_pose(k)};
      }
    }
    from.keyframes_sent = static_cast<std::uint32_t>(g.keyframe_slots());
  }

  void MatchKeyframes(Robot& a) {
    bool changed = false;
    for (const auto& [key, theirs] : a.peer_keyframes) {
      if (!a.tried_keyframes.insert(key).second) continue;
      // The most alike of our keyframes.
      float best = 2.0f, yaw = 0.0f;
      std::uint32_t best_k = 0;
      for (const auto& [k, mine] : a.own_keyframes) {
        const auto sc = core::ScanContextDistance(mine, theirs.first);
        if (sc && sc->distance < best) {
          best = sc->distance;
          yaw = sc->yaw_rad;
          best_k = k;
        }
      }
      if (best > kKeyframeScThreshold) continue;
      ++a.proposals;
      Robot& b = *robots[static_cast<std::size_t>(key.first)];
      accounting.Add(kCloudRequest, a.index, b.index, core::kRoomCloudRequestBytes);
      const auto cloud_b = b.mapper.keyframe_cloud(key.second);
      core::RoomCloudHeader header{b.id(), key.second, 0, cloud_encoding, 0.01f};
      auto n = core::EncodeRoomCloud(header, cloud_b, buffer);
      if (!n) continue;
      accounting.Add(kKeyframeCloud, b.index, a.index, *n);
      if (!core::DecodeRoomCloud(std::span(buffer.data(), *n), decoded_cloud)) {
        ++accounting.malformed;
        continue;
      }
      core::RoomMatch m;
      m.robot_a = a.id();
      m.robot_b = b.id();
      m.room_a = best_k;
      m.room_b = key.second;
      m.sc_distance = best;
      if (!matcher.FineAlign(a.mapper.keyframe_cloud(best_k),
                             a.mapper.graph().keyframe_pose(best_k), decoded_cloud.span(),
                             theirs.second, static_cast<double>(yaw), m)) {
        ++a.rejected_fine;
        continue;
      }
      a.matches[key.first].push_back(m);
      changed = true;
    }
    if (!changed) return;
    a.collab.Clear();
    a.rejected_consistency = 0;
    for (auto& [b_index, list] : a.matches) {
      std::vector<std::uint32_t> keep(std::min<std::size_t>(list.size(), 64));
      keep.resize(core::ConsistentMatches(list, matcher.config(), keep));
      a.consistent[b_index] = keep;
      a.rejected_consistency += list.size() - keep.size();
      if (keep.empty()) continue;
      const auto robot_b = static_cast<std::uint16_t>(b_index + 1);
      static_cast<void>(a.collab.SetInitial(robot_b, list[keep[0]].T_a_b));
      for (std::uint32_t i : keep)
        static_cast<void>(a.collab.AddOriginMeasurement(robot_b, list[i].T_a_b, 0.03, 0.005));
    }
    static_cast<void>(a.collab.Solve());
  }

  // The view of robot a: merged robots, their origins, accepted matches.
  bool Merged(const Robot& a, int b_index) const {
    const auto robot = static_cast<std::uint16_t>(b_index + 1);
    return keyframes ? a.collab.has_robot(robot) : a.session.merged(robot);
  }
  Eigen::Isometry3d Origin(const Robot& a, int b_index) const {
    const auto robot = static_cast<std::uint16_t>(b_index + 1);
    return keyframes ? a.collab.T_self_robot(robot) : a.session.T_self_robot(robot);
  }
  std::vector<core::RoomMatch> Accepted(Robot& a, int b_index) {
    std::vector<core::RoomMatch> out;
    if (keyframes) {
      for (std::uint32_t i : a.consistent[b_index]) out.push_back(a.matches[b_index][i]);
    } else {
      out.resize(64);
      out.resize(a.session.ConsistentMatches(static_cast<std::uint16_t>(b_index + 1), out));
    }
    return out;
  }
};

}  // namespace

int main(int argc, char** argv) {
  std::string run, out_dir;
  Mission mission;
  core::CollabSessionConfig session_config;
  std::string mode_name = "rooms-walls-fine";
  double every_s = 10.0;
  std::map<int, double> delays_s;  // robot id -> start delay
  bool markdown = false, step_given = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--run" && i + 1 < argc)
      run = argv[++i];
    else if (a == "--exchange-every-s" && i + 1 < argc)
      every_s = std::atof(argv[++i]);
    else if (a == "--hypotheses" && i + 1 < argc) {
      // walls (the default): competing match sets told apart by the walls; count: by size alone.
      const std::string h = argv[++i];
      if (h != "walls" && h != "count") {
        std::fprintf(stderr, "collab: --hypotheses takes walls or count\n");
        return 2;
      }
      if (h == "count") {
        std::fprintf(stderr, "collab: --hypotheses count is gone: the merge rule decides (docs/multi-robot.md)\n");
        return 2;
      }
    } else if (a == "--delay-s" && i + 1 < argc) {
      // ROBOT=SECONDS: that robot starts later in mission time (a late joiner when longer than
      // the others' missions: it arrives with its whole map).
      int robot = 0;
      double delay = 0;
      if (std::sscanf(argv[++i], "%d=%lf", &robot, &delay) != 2 || robot < 1 || !(delay >= 0)) {
        std::fprintf(stderr, "collab: --delay-s takes ROBOT=SECONDS\n");
        return 2;
      }
      delays_s[robot] = delay;
    }
    else if (a == "--markdown")
      markdown = true;
    else if (a == "--out" && i + 1 < argc)
      out_dir = argv[++i];
    else if (a == "--mode" && i + 1 < argc) {
      mode_name = argv[++i];
      if (mode_name == "rooms")
        session_config.mode = {false, false};
      else if (mode_name == "rooms-fine")
        session_config.mode = {false, true};
      else if (mode_name == "rooms-walls")
        session_config.mode = {true, false};
      else if (mode_name == "rooms-walls-fine")
        session_config.mode = {true, true};
      else if (mode_name == "keyframes")
        mission.keyframes = true;
      else {
        std::fprintf(stderr, "collab: unknown mode %s\n", mode_name.c_str());
        return 2;
      }
    } else if (a == "--cloud" && i + 1 < argc) {
      const std::string c = argv[++i];
      if (c != "f32" && c != "q16" && c != "q8") {
        std::fprintf(stderr, "collab: --cloud is f32, q16 or q8\n");
        return 2;
      }
      mission.cloud_encoding = c == "f32"   ? core::CloudEncoding::kFloat32
                               : c == "q16" ? core::CloudEncoding::kQuantised16
                                            : core::CloudEncoding::kQuantised8;
      if (c == "q8" && !step_given) session_config.cloud_step_m = 0.05f;
    } else if (a == "--feedback" && i + 1 < argc) {
      const std::string f = argv[++i];
      if (f != "on" && f != "off") {
        std::fprintf(stderr, "collab: --feedback is on or off\n");
        return 2;
      }
      mission.feedback = f == "on";
    } else if (a == "--cloud-step" && i + 1 < argc) {
      session_config.cloud_step_m = static_cast<float>(std::atof(argv[++i]));
      step_given = true;
    } else {
      std::fprintf(
          stderr,
          "usage: msgraphs_collab --run DIR [--mode "
          "rooms|rooms-fine|rooms-walls|rooms-walls-fine|keyframes] "
          "[--cloud f32|q16|q8] [--cloud-step 0.01] [--feedback on|off] [--exchange-every-s 10] "
          "[--delay-s ROBOT=SECONDS]... [--hypotheses walls|count] "
          "[--out DIR] "
          "[--markdown]\n");
      return 2;
    }
  }
  if (run.empty() || !(every_s > 0)) {
    std::fprintf(stderr, "collab: --run DIR is required\n");
    return 2;
  }
  session_config.cloud_encoding = mission.cloud_encoding;
  if (auto s = mission.matcher.Init({}); !s) {
    std::fprintf(stderr, "collab: %s\n", s.error().detail);
    return 1;
  }
  for (int i = 0; i < 10; ++i) {
    const fs::path dir = fs::path(run) / ("robot" + std::to_string(i + 1));
    if (!fs::exists(dir / "velodyne.pcap")) break;
    auto r = std::make_unique<Robot>();
    r->index = i;
    r->scans = drivers::velodyne::RecordedScans::Open((dir / "velodyne.pcap").string());
    auto candump = drivers::can_odometry::CandumpFileReader::Open((dir / "odometry.log").c_str());
    if (!r->scans || !candump) {
      std::fprintf(stderr, "collab: cannot open %s\n", dir.c_str());
      return 1;
    }
    r->candump.emplace(std::move(*candump));
    core::LocalMapperConfig config;
    session_config.robot = r->id();
    Status s = r->mapper.Init(config);
    if (s) s = r->session.Init(session_config, config.graph, -config.base_height_m);
    if (s) s = r->collab.Init({}, r->id());
    if (!s) {
      std::fprintf(stderr, "collab: %s\n", s.error().detail);
      return 1;
    }
    r->truth = tools::ReadTum((dir / "ground_truth.tum").string());
    if (auto d = delays_s.find(r->id()); d != delays_s.end()) r->delay_s = d->second;
    Advance(*r);
    mission.robots.push_back(std::move(r));
  }
  if (mission.robots.size() < 2) {
    std::fprintf(stderr, "collab: %s holds fewer than two robots\n", run.c_str());
    return 2;
  }
  const auto t0 = std::chrono::steady_clock::now();
  double next_exchange = every_s;
  // Cumulative bytes per message type after each exchange, for --out DIR/bytes.csv.
  std::vector<std::pair<double, std::array<std::uint64_t, kMessageTypes>>> timeline;
  for (;;) {
    Robot* next = nullptr;
    for (auto& r : mission.robots) {
      if (!r->scans_done && (next == nullptr || Now(*r) < Now(*next))) next = r.get();
    }
    if (next == nullptr) break;
    const double t = Now(*next);
    if (t >= next_exchange) {
      mission.now_s = t;
      mission.Exchange();
      timeline.push_back({t, {}});
      for (int k = 0; k < kMessageTypes; ++k)
        timeline.back().second[static_cast<std::size_t>(k)] = mission.accounting.Total(k);
      // The next period after t (a delayed robot can leave a gap of several periods).
      next_exchange = (std::floor(t / every_s) + 1) * every_s;
    }
    ProcessScan(*next);
  }
  for (auto& r : mission.robots) static_cast<void>(r->mapper.Finish());
  mission.Exchange();
  // The last exchange's wall priors into the final maps.
  if (mission.feedback && !mission.keyframes) {
    for (auto& r : mission.robots) static_cast<void>(r->mapper.Finish());
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  // ---- evaluation from robot 1 ----
  Robot& self = *mission.robots[0];
  std::vector<Eigen::Isometry3d> T_world_map(mission.robots.size());
  std::vector<tools::StampedPose> aggregated, aggregated_truth;
  std::size_t merged = 1;
  std::uint64_t accepted = 0, wrong = 0;
  for (auto& r : mission.robots) {
    std::vector<tools::StampedPose> kf;
    const core::SGraph& g = r->mapper.graph();
    for (std::uint32_t k = 0; k < g.keyframe_slots(); ++k) {
      if (g.keyframe_active(k)) kf.push_back({g.keyframe_stamp(k), g.keyframe_pose(k)});
    }
    std::sort(kf.begin(), kf.end(), [](const auto& a, const auto& b) { return a.t < b.t; });
    const auto own = tools::ComputeAte(kf, r->truth, 0.006);
    T_world_map[static_cast<std::size_t>(r->index)] = own.T_truth_estimate;
    const bool in = r->index == 0 || mission.Merged(self, r->index);
    if (r->index != 0 && in) ++merged;
    if (!in) continue;
    const Eigen::Isometry3d T_1_b =
        r->index == 0 ? Eigen::Isometry3d::Identity() : mission.Origin(self, r->index);
    if (!out_dir.empty()) {
      std::vector<tools::StampedPose> in_1;
      for (const auto& p : kf) in_1.push_back({p.t, T_1_b * p.T});
      fs::create_directories(out_dir);
      static_cast<void>(tools::WriteTum(
          (fs::path(out_dir) / ("robot" + std::to_string(r->index + 1) + "_in_robot1.tum"))
              .string(),
          in_1));
    }
    for (const auto& p : kf) {
      // Stamps differ per robot clock: pair each keyframe with its own robot's truth here.
      if (const tools::StampedPose* t = tools::Nearest(r->truth, p.t, 0.006)) {
        const double stamp = static_cast<double>(aggregated.size());
        aggregated.push_back({stamp, T_1_b * p.T});
        aggregated_truth.push_back({stamp, t->T});
      }
    }
  }
  if (!out_dir.empty()) {
    fs::create_directories(out_dir);
    if (std::FILE* f = std::fopen((fs::path(out_dir) / "bytes.csv").c_str(), "w")) {
      std::fprintf(f, "mission_time_s");
      for (int k = 0; k < kMessageTypes; ++k) std::fprintf(f, ",%s", kTypeNames[k]);
      std::fprintf(f, "\n");
      for (const auto& [t, bytes] : timeline) {
        std::fprintf(f, "%.1f", t);
        for (std::uint64_t b : bytes) std::fprintf(f, ",%llu", static_cast<unsigned long long>(b));
        std::fprintf(f, "\n");
      }
      std::fclose(f);
    }
  }
  // Accepted matches (consistent sets) of every robot, checked against the truth.
  std::map<std::pair<int, int>, int> wrong_in_view;  // (viewer, peer) -> wrong accepted matches
  for (auto& r : mission.robots) {
    for (auto& b : mission.robots) {
      if (b == r) continue;
      for (const core::RoomMatch& m : mission.Accepted(*r, b->index)) {
        const Eigen::Isometry3d truth = T_world_map[static_cast<std::size_t>(r->index)].inverse() *
                                        T_world_map[static_cast<std::size_t>(b->index)];
        const Eigen::Isometry3d e = truth.inverse() * m.T_a_b;
        ++accepted;
        if (e.translation().head<2>().norm() > 0.5 || Eigen::AngleAxisd(e.linear()).angle() > 0.1) {
          ++wrong;
          ++wrong_in_view[{r->id(), b->id()}];
        }
      }
    }
  }
  std::uint64_t proposed = 0, rejected_fine = 0, rejected_consistency = 0, rejected_anchored = 0,
                checked_anchored = 0;
  for (auto& r : mission.robots) {
    if (mission.keyframes) {
      proposed += r->proposals;
      rejected_fine += r->rejected_fine;
      rejected_consistency += r->rejected_consistency;
      continue;
    }
    const core::CollabSessionStats& st = r->session.stats();
    proposed += st.proposals;
    rejected_fine += st.rejected_fine;
    rejected_consistency += st.rejected_consistency;
    rejected_anchored += st.rejected_anchored;
    checked_anchored += st.checked_anchored;
  }
  const auto ate = tools::ComputeAte(aggregated, aggregated_truth, 0.5);
  const double mb = static_cast<double>(mission.accounting.Total()) / 1e6;
  if (markdown) {
    std::printf("| %s | %zu | %s | %zu / %zu | %.3f | %.3f | %llu / %llu | %llu |\n", run.c_str(),
                mission.robots.size(), mode_name.c_str(), merged, mission.robots.size(), ate.rmse,
                mb, static_cast<unsigned long long>(accepted - wrong),
                static_cast<unsigned long long>(accepted), static_cast<unsigned long long>(wrong));
    return 0;
  }
  std::printf("mission %s: %zu robots, mode %s, %.1f s\n", run.c_str(), mission.robots.size(),
              mode_name.c_str(), seconds);
  std::printf(
      "robot 1 merged %zu of %zu robots; aggregated ATE %.3f m over %zu keyframes (max %.3f m)\n",
      merged, mission.robots.size(), ate.rmse, ate.poses, ate.max);
  for (auto& r : mission.robots) {
    if (r->index == 0) continue;
    if (!mission.Merged(self, r->index)) {
      std::printf("  robot %d: not merged\n", r->index + 1);
      continue;
    }
    const Eigen::Isometry3d truth =
        T_world_map[0].inverse() * T_world_map[static_cast<std::size_t>(r->index)];
    const Eigen::Isometry3d e = truth.inverse() * mission.Origin(self, r->index);
    const std::size_t factors = mission.keyframes
                                    ? self.collab.factors(r->id())
                                    : self.session.collaborative_graph().factors(r->id());
    std::printf("  robot %d: origin error %.3f m (z %+.3f m), %.2f deg (%zu factors)\n",
                r->index + 1, e.translation().head<2>().norm(), e.translation().z(),
                Eigen::AngleAxisd(e.linear()).angle() * 180.0 / 3.14159265358979, factors);
  }
  std::printf(
      "room matches (all robots): %llu proposed by Scan Context, %llu rejected by fine alignment, "
      "%llu checked against a merged estimate (%llu rejected), %llu rejected by the consistency "
      "check, %llu accepted, %llu of them wrong against the truth\n",
      static_cast<unsigned long long>(proposed), static_cast<unsigned long long>(rejected_fine),
      static_cast<unsigned long long>(checked_anchored),
      static_cast<unsigned long long>(rejected_anchored),
      static_cast<unsigned long long>(rejected_consistency),
      static_cast<unsigned long long>(accepted), static_cast<unsigned long long>(wrong));
  // Every robot's view of every other: where competing hypotheses were weighed by the walls, or
  // where a pair stayed unmerged.
  for (auto& r : mission.robots) {
    if (mission.keyframes) break;
    for (std::size_t i = 0; i < r->session.peers(); ++i) {
      const core::CollabPeerStats p = r->session.peer_stats(i);
      const int wrong_here = wrong_in_view[{r->id(), p.robot}];
      std::printf("  view of robot %d: robot %u %s (%s), %zu hypotheses (%zu refuted); leader: walls "
                  "agree %.1f m, %.1f m in the weakest direction, %.1f m conflict; rival %.1f m%s; %d "
                  "accepted matches wrong\n",
                  r->index + 1, p.robot, p.merged ? "merged" : "NOT merged", core::ToString(p.verdict),
                  p.hypotheses, p.refuted, p.leader.agreement_m, p.leader.constraint_m, p.leader.conflict_m,
                  p.rival.agreement_m, p.rival_from_symmetry ? " (symmetry)" : "", wrong_here);
    }
  }
  std::printf("data exchanged: %.3f MB in total, %llu messages malformed\n", mb,
              static_cast<unsigned long long>(mission.accounting.malformed));
  for (int t = 0; t < kMessageTypes; ++t) {
    std::printf("  %-20s %10.1f kB\n", kTypeNames[t],
                static_cast<double>(mission.accounting.Total(t)) / 1e3);
  }
  for (const auto& from : mission.robots) {
    for (const auto& to : mission.robots) {
      if (from == to) continue;
      std::uint64_t sum = 0;
      for (const auto& [key, n] : mission.accounting.bytes) {
        if (std::get<1>(key) == from->index && std::get<2>(key) == to->index) sum += n;
      }
      std::printf("  robot %d -> robot %d %10.1f kB\n", from->index + 1, to->index + 1,
                  static_cast<double>(sum) / 1e3);
    }
  }
  if (!mission.keyframes) {
    const core::CollabSessionStats& st = self.session.stats();
    std::printf(
        "robot 1 session: %zu own rooms (peak room cloud %zu points), %zu peers, stores %.1f MB; "
        "refused: rooms %llu, clouds too large %llu, descriptors %llu, pending %llu, matches %llu; "
        "cache evictions %llu; solves %llu (%llu failed); marginal wall covariances %llu times "
        "(%llu fell back)\n",
        st.own_rooms, st.room_points_peak, st.peers, static_cast<double>(st.store_bytes) / 1e6,
        static_cast<unsigned long long>(st.rooms_refused),
        static_cast<unsigned long long>(st.room_clouds_too_large),
        static_cast<unsigned long long>(st.descriptors_refused),
        static_cast<unsigned long long>(st.pending_refused),
        static_cast<unsigned long long>(st.matches_refused),
        static_cast<unsigned long long>(st.cache_evictions),
        static_cast<unsigned long long>(st.solves),
        static_cast<unsigned long long>(st.solve_failures),
        static_cast<unsigned long long>(st.marginal_updates),
        static_cast<unsigned long long>(st.marginal_failures));
  }
  return 0;
}
