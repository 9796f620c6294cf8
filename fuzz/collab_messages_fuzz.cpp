// SPDX-License-Identifier: MIT
// libFuzzer target: arbitrary bytes as another robot's message. The first byte picks the kind
// (distilled graph, room descriptor, room cloud request, room cloud, free-space summary, place
// request, place cloud); the rest
// is the message body,
// to which the correct CRC-32 is appended so that the parsers past the checksum are exercised (a
// wrong CRC alone is rejected at once). Invariants: no crash; whatever decodes is finite, within
// the receiver's capacity, with unit wall normals, and merges into a copy; a free-space summary
// that decodes fills exactly its grid with valid states and finite openings; a place request
// has distinct robots, a finite centre and a radius in range; a place cloud's points are finite.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <vector>

#include "msgraphs/core/collab/distilled_codec.hpp"
#include "msgraphs/core/collab/free_space_codec.hpp"
#include "msgraphs/core/collab/place_messages.hpp"
#include "msgraphs/core/collab/room_messages.hpp"
#include "sealed_message.hpp"

using namespace msgraphs;
using namespace msgraphs::core;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const std::vector<std::uint8_t> message = SealedMessage(std::span(data + 1, size - 1));
  const std::span<const std::uint8_t> bytes(message);
  switch (data[0] % 7) {
    case 0: {
      static DistilledGraph known, out;
      static bool init = false;
      if (!init) {
        known.Init(64, 16);
        out.Init(64, 16);
        init = true;
      }
      if (!DecodeDistilled(bytes, out, &known)) break;
      if (out.walls.size() > 64 || out.rooms.size() > 16) std::abort();
      for (const DistilledWall& w : out.walls) {
        if (!w.normal.allFinite() || std::fabs(w.normal.norm() - 1.0) > 1e-6 || !std::isfinite(w.d))
          std::abort();
      }
      if (out.has_floor && (!out.floor_centre.allFinite() || !std::isfinite(out.floor_z_m)))
        std::abort();
      static_cast<void>(ApplyDistilled(out, known));
      if (known.walls.size() > known.walls.capacity()) std::abort();
      break;
    }
    case 1: {
      ScanContext sc;
      if (!DecodeRoomDescriptor(bytes, sc)) break;
      for (int r = 0; r < sc.rings(); ++r) {
        for (int s = 0; s < sc.sectors(); ++s) {
          if (!std::isfinite(sc.cell(r, s))) std::abort();
        }
      }
      break;
    }
    case 2: {
      auto q = DecodeRoomCloudRequest(bytes);
      if (q && (q->from == 0 || q->to == 0 || q->from == q->to)) std::abort();
      break;
    }
    case 4: {
      static FreeSpaceSummary summary;
      static bool init = false;
      if (!init) {
        FreeSpaceSummaryConfig config;
        config.max_cells = 1 << 16;
        config.max_openings = 32;
        if (!summary.Init(config)) std::abort();
        init = true;
      }
      if (!DecodeFreeSpace(bytes, summary)) break;
      if (summary.cells() > (1u << 16) || summary.openings().size() > 32) std::abort();
      for (std::uint8_t c : summary.raw()) {
        if (c > 2) std::abort();
      }
      for (const Opening& o : summary.openings()) {
        if (!o.a.allFinite() || !o.b.allFinite()) std::abort();
      }
      if (!(summary.clearance_m(summary.origin_m()) >= 0.0f)) std::abort();
      break;
    }
    case 5: {
      auto q = DecodePlaceRequest(bytes);
      if (q && (q->from == 0 || q->to == 0 || q->from == q->to || !q->centre_m.allFinite() ||
                !(q->radius_m > 0 && q->radius_m <= kMaxPlaceRadiusM)))
        std::abort();
      break;
    }
    case 6: {
      static BoundedVector<Eigen::Vector3f> points(4096);
      auto h = DecodePlaceCloud(bytes, points);
      if (!h) break;
      if (h->robot == 0 || h->to == 0 || h->robot == h->to || !h->centre_m.allFinite() || points.size() > 4096)
        std::abort();
      for (const Eigen::Vector3f& p : points) {
        if (!p.allFinite()) std::abort();
      }
      break;
    }
    default: {
      static BoundedVector<Eigen::Vector3f> points(4096);
      if (!DecodeRoomCloud(bytes, points)) break;
      for (const Eigen::Vector3f& p : points) {
        if (!p.allFinite()) std::abort();
      }
    }
  }
  return 0;
}
