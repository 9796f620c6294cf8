// SPDX-License-Identifier: MIT
#include "lidar_sim.hpp"

#include <array>
#include <cmath>
#include <cstring>
#include <numbers>
#include <optional>
#include <thread>
#include <vector>

#include "msgraphs/drivers/pcap/pcap_writer.hpp"
#include "msgraphs/drivers/velodyne/packet_format.hpp"
#include "msgraphs/drivers/velodyne/sensor_model.hpp"
#include "random.hpp"

namespace msgraphs::sim {
namespace {

namespace vel = msgraphs::drivers::velodyne;
using Packet = std::array<std::uint8_t, vel::kDataPacketBytes>;

constexpr double kPacketS = 12 * 110.592e-6;
constexpr double kSequenceS = 55.296e-6;
constexpr double kLaserS = 2.304e-6;
constexpr int kChunkPackets = 1500;  // ~2 s of data per work item

struct Chunk {
  std::vector<Packet> packets;
  std::vector<double> first_firing_t;
  LidarSimStats stats;
  WallVisibility visibility;  // this chunk's wall hits (summed in any order: deterministic)
};

void RenderChunk(const Scene& scene,
                 const Trajectory& trajectory,
                 const LidarSimConfig& config,
                 const RobotClocks& clocks,
                 std::uint64_t seed,
                 int robot,
                 std::int64_t first_packet,
                 std::int64_t count,
                 double azimuth_phase_deg,
                 const PeopleScene* people,
                 bool record_visibility,
                 Chunk& chunk) {
  const vel::ModelInfo& model = vel::GetModelInfo(vel::SensorModel::kVlp16);
  Random rng = Random::Stream(seed, 0x6C696461 + static_cast<std::uint64_t>(robot),  // "lida"
                              static_cast<std::uint64_t>(first_packet));
  Scene::Scratch scratch = scene.MakeScratch();
  std::array<double, 16> cos_el{}, sin_el{}, offset{};
  for (int l = 0; l < 16; ++l) {
    cos_el[static_cast<std::size_t>(l)] =
        std::cos(model.laser[static_cast<std::size_t>(l)].elevation_rad);
    sin_el[static_cast<std::size_t>(l)] =
        std::sin(model.laser[static_cast<std::size_t>(l)].elevation_rad);
    offset[static_cast<std::size_t>(l)] =
        model.laser[static_cast<std::size_t>(l)].vertical_offset_m;
  }
  const double deg_per_s = config.rpm * 6.0;
  const double cos_grazing = std::cos(config.grazing_dropout_deg * std::numbers::pi / 180.0);
  chunk.packets.resize(static_cast<std::size_t>(count));
  chunk.first_firing_t.resize(static_cast<std::size_t>(count));
  const std::size_t n_people = people != nullptr ? people->size() : 0;
  std::vector<Eigen::Vector2d> person_xy(n_people), person_v(n_people);
  for (std::int64_t k = 0; k < count; ++k) {
    const double t_packet = static_cast<double>(first_packet + k) * kPacketS;
    Packet& p = chunk.packets[static_cast<std::size_t>(k)];
    p.fill(0);
    chunk.first_firing_t[static_cast<std::size_t>(k)] = t_packet;
    for (int b = 0; b < vel::kBlocksPerPacket; ++b) {
      std::uint8_t* block = p.data() + static_cast<std::size_t>(b) * vel::kBlockBytes;
      block[0] = 0xFF;
      block[1] = 0xEE;
      const double t_block = t_packet + 2 * b * kSequenceS;
      const double az_block = std::fmod(azimuth_phase_deg + deg_per_s * t_block, 360.0);
      vel::WriteU16Le(block + 2, static_cast<std::uint16_t>(
                                     static_cast<int>(std::lround(az_block * 100.0)) % 36000));
      for (int s = 0; s < 2; ++s) {
        const double t_fire = t_block + s * kSequenceS;
        const Eigen::Isometry3d T_world_lidar = trajectory.Pose(t_fire) * config.T_base_lidar;
        const Eigen::Matrix3d& R = T_world_lidar.linear();
        if (n_people > 0)
          people->Snapshot(trajectory.start_s() + t_fire, person_xy.data(), person_v.data());
        for (int l = 0; l < 16; ++l) {
          const auto li = static_cast<std::size_t>(l);
          const double t_laser = t_fire + l * kLaserS;
          const double az = (azimuth_phase_deg + deg_per_s * t_laser) * std::numbers::pi / 180.0;
          // The ROS lidar frame: x towards azimuth 0, y left, azimuth clockwise from above.
          const Eigen::Vector3d dir_lidar(cos_el[li] * std::cos(az), -cos_el[li] * std::sin(az),
                                          sin_el[li]);
          const Eigen::Vector3d origin = T_world_lidar * Eigen::Vector3d(0, 0, offset[li]);
          const Eigen::Vector3d dir = R * dir_lidar;
          ++chunk.stats.rays;
          std::uint16_t units = 0;
          std::uint8_t reflectivity = 0;
          std::optional<Hit> hit = scene.Cast(origin, dir, config.max_range_m, scratch);
          if (n_people > 0) {
            Hit nearest =
                hit ? *hit : Hit{config.max_range_m, {0, 0, 1}, Material::kPainted, -1, 0, -1};
            if (people->Cast(person_xy.data(), person_v.data(), t_laser - t_fire, origin, dir,
                             nearest))
              hit = nearest;
          }
          if (hit) {
            const double cos_incidence = -hit->normal.dot(dir);
            if (cos_incidence < cos_grazing || rng.Chance(config.dropout_probability)) {
              ++chunk.stats.dropouts;
            } else {
              const double range = hit->range_m + rng.Normal(config.range_noise_sigma_m);
              const double u = std::round(range / vel::kDistanceUnitM);
              if (range > 0.0 && range <= config.max_range_m && u >= 1.0 && u <= 65535.0) {
                units = static_cast<std::uint16_t>(u);
                const double r =
                    Reflectivity(hit->material) * (0.35 + 0.65 * cos_incidence) + rng.Normal(2.0);
                reflectivity = static_cast<std::uint8_t>(std::clamp(std::lround(r), 1L, 255L));
                ++chunk.stats.returns;
                if (hit->person >= 0) ++chunk.stats.person_returns;
                if (hit->wall >= 0 && hit->face != 0) {
                  ++chunk.stats.wall_returns;
                  if (record_visibility) chunk.visibility.Record(*hit, origin + dir * hit->range_m);
                }
              }
            }
          }
          std::uint8_t* rec = block + 4 + static_cast<std::size_t>(s * 16 + l) * vel::kChannelBytes;
          vel::WriteU16Le(rec, units);
          rec[2] = reflectivity;
        }
      }
    }
    vel::WriteU32Le(p.data() + vel::kTimestampOffset, clocks.LidarTimeOfHourUs(t_packet));
    p[vel::kReturnModeOffset] = static_cast<std::uint8_t>(vel::ReturnMode::kStrongest);
    p[vel::kProductIdOffset] = static_cast<std::uint8_t>(vel::ProductId::kVlp16);
  }
  chunk.stats.data_packets = static_cast<std::uint64_t>(count);
}

std::array<std::uint8_t, vel::kPositionPacketBytes> PositionPacket(std::uint32_t toh_us) {
  std::array<std::uint8_t, vel::kPositionPacketBytes> p{};
  p[187] = 41;  // top board temperature, deg C
  p[188] = 38;  // bottom board
  vel::WriteU32Le(p.data() + 198, toh_us);
  p[202] = 0;  // PPS absent: indoors, no GPS; the NMEA field stays empty
  return p;
}

}  // namespace

bool RenderLidar(const Scene& scene,
                 const Trajectory& trajectory,
                 const LidarSimConfig& config,
                 const RobotClocks& clocks,
                 std::uint64_t seed,
                 int robot,
                 const std::string& pcap_path,
                 LidarSimStats& stats,
                 std::string& error,
                 const PeopleScene* people,
                 WallVisibility* visibility) {
  namespace pcap = msgraphs::drivers::pcap;
  auto writer = pcap::PcapFileWriter::Create(
      pcap_path.c_str(), config.nanosecond_pcap ? pcap::TimestampPrecision::kNanoseconds
                                                : pcap::TimestampPrecision::kMicroseconds);
  if (!writer) {
    error = pcap_path + ": " + writer.error().detail;
    return false;
  }
  Random rng = Random::Stream(seed, 0x6C617465 + static_cast<std::uint64_t>(robot));  // "late"
  const double azimuth_phase_deg = rng.Uniform(0, 360);
  const auto total = static_cast<std::int64_t>(std::floor(trajectory.duration_s() / kPacketS)) - 1;
  const Ipv4Endpoint sensor{0xC0A801C9, vel::kDefaultDataPort};  // 192.168.1.201
  const Ipv4Endpoint broadcast{0xFFFFFFFF, vel::kDefaultDataPort};
  const Ipv4Endpoint sensor_position{0xC0A801C9, vel::kDefaultPositionPort};
  const Ipv4Endpoint broadcast_position{0xFFFFFFFF, vel::kDefaultPositionPort};
  double next_position_t = 0.0;

  const int threads = std::max(1, config.threads);
  std::vector<Chunk> chunks(static_cast<std::size_t>(threads));
  for (std::int64_t first = 0; first < total; first += kChunkPackets * threads) {
    std::vector<std::thread> workers;
    int used = 0;
    for (int w = 0; w < threads; ++w) {
      const std::int64_t start = first + static_cast<std::int64_t>(w) * kChunkPackets;
      if (start >= total) break;
      const std::int64_t count = std::min<std::int64_t>(kChunkPackets, total - start);
      ++used;
      workers.emplace_back([&, w, start, count] {
        Chunk& c = chunks[static_cast<std::size_t>(w)];
        c.stats = {};
        if (visibility != nullptr) {
          if (c.visibility.walls() == 0) c.visibility = *visibility;
          c.visibility.Clear();
        }
        RenderChunk(scene, trajectory, config, clocks, seed, robot, start, count, azimuth_phase_deg,
                    people, visibility != nullptr, c);
      });
    }
    for (auto& t : workers) t.join();
    // Write in time order; position packets interleave at their own rate.
    for (int w = 0; w < used; ++w) {
      Chunk& c = chunks[static_cast<std::size_t>(w)];
      for (std::size_t k = 0; k < c.packets.size(); ++k) {
        const double t_done =
            c.first_firing_t[k] + kPacketS;  // the packet leaves after its last firing
        while (next_position_t <= t_done) {
          const auto pos = PositionPacket(clocks.LidarTimeOfHourUs(next_position_t));
          const double latency = 150e-6 + std::fabs(rng.Normal(40e-6));
          if (Status s = writer->WriteUdp(clocks.Host(next_position_t + latency), sensor_position,
                                          broadcast_position, pos);
              !s) {
            error = pcap_path + ": " + s.error().detail;
            return false;
          }
          ++stats.position_packets;
          next_position_t += config.position_packet_period_s;
        }
        const double latency = 120e-6 + std::fabs(rng.Normal(30e-6));
        if (Status s =
                writer->WriteUdp(clocks.Host(t_done + latency), sensor, broadcast, c.packets[k]);
            !s) {
          error = pcap_path + ": " + s.error().detail;
          return false;
        }
      }
      stats.data_packets += c.stats.data_packets;
      stats.rays += c.stats.rays;
      stats.returns += c.stats.returns;
      stats.dropouts += c.stats.dropouts;
      stats.person_returns += c.stats.person_returns;
      stats.wall_returns += c.stats.wall_returns;
      if (visibility != nullptr) visibility->Merge(c.visibility);
    }
  }
  if (Status s = writer->Close(); !s) {
    error = pcap_path + ": " + s.error().detail;
    return false;
  }
  return true;
}

}  // namespace msgraphs::sim
