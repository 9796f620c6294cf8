// SPDX-License-Identifier: MIT
// The S-Graph's snapshot (SGraph::Save / Load, docs/s-graph.md "Snapshots").
//
// What is saved is the graph's own state, not Ceres': every node and factor record with its
// slot, the free lists in their order, the held sums, the counters, and each factor's
// measurement read back from its cost function. Load rebuilds the Ceres problem from them; the
// graph's solves hand Ceres its blocks by slot, never in the problem's order (s_graph_solve.cpp),
// so a loaded graph goes on exactly as the saved one would have.
//
// Layout: a header (magic, version, payload bytes, payload CRC-32), then the payload: the
// config (a loaded graph must have been initialised with the same), the scalars and counters,
// the keyframe, plane, room and factor records up to their high-water marks, the free lists.
// Each record is written and read by one visitor (Io), so the two sides cannot disagree.
#include <ceres/ceres.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>
#include <cstring>

#include "msgraphs/base/crc32.hpp"
#include "msgraphs/base/snapshot_archive.hpp"
#include "msgraphs/base/snapshot_header.hpp"
#include "msgraphs/core/graph/s_graph.hpp"
#include "s_graph_impl.hpp"

namespace msgraphs::core {
namespace {

constexpr SnapshotMagic kMagic{'M', 'S', 'G', 'S', 'G', 'R', 'P', 'H'};
constexpr std::uint32_t kVersion = 2;  // 2: sparsify_plane_share and its counters
constexpr std::size_t kHeaderBytes = kSnapshotHeaderBytes;
constexpr std::size_t kMaxBlocks = 9;   // a four-wall room: centre and four walls' two blocks
constexpr std::size_t kMaxValues = 43;  // a relative pose: rotation, translation, 6x6 root

// A new field in one of these must be added to its visitor below, then the size here.
static_assert(sizeof(void*) != 8 || sizeof(SGraphConfig) == 144, "SGraphConfig changed: see Io");
static_assert(sizeof(void*) != 8 || sizeof(MapPlane) == 184, "MapPlane changed: see Io");
static_assert(sizeof(void*) != 8 || sizeof(MapRoom) == 80, "MapRoom changed: see Io");
static_assert(std::is_trivially_copyable_v<SGraphStats>, "SGraphStats is saved whole");

enum class BlockOf : std::uint8_t { kKeyframeQ, kKeyframeT, kPlaneN, kPlaneD, kRoom, kFloor };
enum class LossOf : std::uint8_t { kNone, kRelative, kLoop, kPlane, kRoom };
enum class CostOf : std::uint8_t {
  kRelative,
  kPlane,
  kRoom,
  kCorridor,
  kWallWall,
  kFloorRoom,
  kPlanePrior
};
constexpr std::uint8_t kCostKinds = 7;

template <class Ar>
void Io(Ar& ar, SGraphConfig& c) {
  ar(c.max_keyframes);
  ar(c.max_planes);
  ar(c.max_rooms);
  ar(c.max_factors);
  ar(c.huber_relative_pose);
  ar(c.huber_loop_closure);
  ar(c.huber_plane);
  ar(c.huber_room);
  ar(c.room_sigma_m);
  ar(c.wall_wall_sigma);
  ar(c.floor_room_sigma_m);
  ar(c.local_window_keyframes);
  ar(c.local_max_iterations);
  ar(c.local_max_seconds);
  IoBool(ar, c.incremental_held_sums);
  ar(c.sparsify_plane_share);
  ar(c.full_max_iterations);
  ar(c.full_max_seconds);
}

template <class Ar>
void Io(Ar& ar, KeyframeNode& k) {
  ar(k.q, 4);
  ar(k.t, 3);
  ar(k.stamp_s);
  ar(k.prev);
  ar(k.next);
  ar(k.loop_factors);
  ar(k.measurement_from_prev.matrix().data(), 16);
  ar(k.information_from_prev.data(), 36);
  IoBool(ar, k.active);
}

template <class Ar>
void Io(Ar& ar, MapPlane& p) {
  ar(p.normal.data(), 3);
  ar(p.d);
  ar(p.information.data(), 9);
  ar(p.basis_u.data(), 3);
  ar(p.basis_v.data(), 3);
  IoEnum(ar, p.plane_class, 3);
  ar(p.observations);
  ar(p.live_observations);
  ar(p.last_observed_s);
  IoBool(ar, p.active);
}

template <class Ar>
void Io(Ar& ar, PlaneNode& p) {
  ar(p.n, 3);
  ar(p.d, 1);
  Io(ar, p.info);
  IoBool(ar, p.in_problem);
  ar(p.held_H.data(), 16);
  ar(p.held_g.data(), 4);
  ar(p.held_observations);
  ar(p.held_epoch);
  ar(p.held_before_s);
}

template <class Ar>
void Io(Ar& ar, RoomNode& r) {
  ar(r.c, 2);
  IoEnum(ar, r.info.shape, 2);
  ar(r.info.centre.data(), 2);
  ar(r.info.walls.data(), 4);
  ar(r.info.corridor_anchor.data(), 2);
  IoBool(ar, r.info.active);
  ar(r.factor);
  ar(r.floor_factor);
  IoBool(ar, r.in_problem);
}

template <class Ar>
void Io(Ar& ar, FactorRecord& f) {
  IoEnum(ar, f.kind, 6);
  IoEnum(ar, f.relative, 4);
  ar(f.a);
  ar(f.b);
  IoBool(ar, f.active);
  IoBool(ar, f.chain);
}

// The measurements inside the cost functions.
template <class Ar>
void Io(Ar& ar, sgraph::RelativePoseResidual& z) {
  ar(z.q_z.coeffs().data(), 4);
  ar(z.t_z.data(), 3);
  ar(z.sqrt_information.data(), 36);
}
template <class Ar>
void Io(Ar& ar, sgraph::PlaneResidual& z) {
  ar(z.basis_u.data(), 3);
  ar(z.basis_v.data(), 3);
  ar(z.d_measured);
  ar(z.sqrt_information.data(), 9);
}
template <class Ar>
void Io(Ar& ar, sgraph::PlanePriorResidual& z) {
  ar(z.basis_u.data(), 3);
  ar(z.basis_v.data(), 3);
  ar(z.d_prior);
  ar(z.sqrt_information.data(), 9);
}
template <class Ar>
void Io(Ar& ar, sgraph::RoomResidual& z) {
  ar(z.inv_sigma);
}
template <class Ar>
void Io(Ar& ar, sgraph::CorridorResidual& z) {
  ar(z.anchor.data(), 2);
  ar(z.inv_sigma);
}
template <class Ar>
void Io(Ar& ar, sgraph::WallWallResidual& z) {
  ar(z.inv_sigma);
}
template <class Ar>
void Io(Ar& ar, sgraph::FloorRoomResidual& z) {
  ar(z.offset.data(), 2);
  ar(z.inv_sigma);
}

// A free list or index list: its length, then its entries (Init reserved the capacity).
template <class Ar>
void IoList(Ar& ar, std::vector<std::int32_t>& list, std::size_t max) {
  std::size_t n = list.size();
  IoCount(ar, n, std::min(max, list.capacity()));
  if constexpr (Ar::kLoading) list.resize(n);  // within the capacity Init reserved
  ar(list.data(), list.size());
}

// A parameter block named by what it belongs to.
struct BlockRef {
  BlockOf of = BlockOf::kFloor;
  std::uint32_t index = 0;
};

}  // namespace

// The parts of Save and Load that need the graph's private state.
struct SGraph::SnapshotAccess {
  // The scalars beside the stores.
  template <class Ar>
  static void IoScalars(Ar& ar, SGraph::Impl& m) {
    ar(m.keyframe_high_water);
    ar(m.newest);
    ar(m.origin);
    ar(m.active_keyframes);
    ar(m.plane_count);
    ar(m.room_count);
    ar(m.floor_c, 2);
    IoBool(ar, m.floor_active);
    ar(m.factor_high_water);
    ar(m.active_factors);
    ar(m.held_epoch);
    IoBool(ar, m.prior_pull);
    ar(m.prior_adds);
    // The revision is this process's count of changes, not the graph's: not saved (Load moves
    // it past the loading graph's own).
    SGraphStats stats = m.stats;
    stats.revision = 0;
    ar(stats);
    if constexpr (Ar::kLoading) m.stats = stats;
  }

  static bool Name(const SGraph::Impl& m, const double* block, BlockRef& ref) {
    const auto in = [](const auto& store, const double* p, std::size_t& at) {
      using Node = typename std::decay_t<decltype(store)>::value_type;
      const auto* base = reinterpret_cast<const unsigned char*>(store.data());
      const auto* q = reinterpret_cast<const unsigned char*>(p);
      if (q < base || q >= base + store.size() * sizeof(Node)) return false;
      at = static_cast<std::size_t>(q - base) / sizeof(Node);
      return true;
    };
    std::size_t at = 0;
    if (in(m.keyframes, block, at)) {
      ref = {block == m.keyframes[at].q ? BlockOf::kKeyframeQ : BlockOf::kKeyframeT,
             static_cast<std::uint32_t>(at)};
      return block == m.keyframes[at].q || block == m.keyframes[at].t;
    }
    if (in(m.planes, block, at)) {
      ref = {block == m.planes[at].n ? BlockOf::kPlaneN : BlockOf::kPlaneD,
             static_cast<std::uint32_t>(at)};
      return block == m.planes[at].n || block == m.planes[at].d;
    }
    if (in(m.rooms, block, at)) {
      ref = {BlockOf::kRoom, static_cast<std::uint32_t>(at)};
      return block == m.rooms[at].c;
    }
    ref = {BlockOf::kFloor, 0};
    return block == m.floor_c;
  }

  // The block a reference names, when it is in the loaded graph's problem; its size.
  static double* Resolve(SGraph::Impl& m, const BlockRef& ref, int& size) {
    const std::size_t i = ref.index;
    switch (ref.of) {
      case BlockOf::kKeyframeQ:
      case BlockOf::kKeyframeT:
        if (i >= m.keyframe_high_water || !m.keyframes[i].active) return nullptr;
        size = ref.of == BlockOf::kKeyframeQ ? 4 : 3;
        return ref.of == BlockOf::kKeyframeQ ? m.keyframes[i].q : m.keyframes[i].t;
      case BlockOf::kPlaneN:
      case BlockOf::kPlaneD:
        if (i >= m.plane_count || !m.planes[i].in_problem) return nullptr;
        size = ref.of == BlockOf::kPlaneN ? 3 : 1;
        return ref.of == BlockOf::kPlaneN ? m.planes[i].n : m.planes[i].d;
      case BlockOf::kRoom:
        if (i >= m.room_count || !m.rooms[i].in_problem) return nullptr;
        size = 2;
        return m.rooms[i].c;
      case BlockOf::kFloor:
        if (!m.problem->HasParameterBlock(m.floor_c)) return nullptr;
        size = 2;
        return m.floor_c;
    }
    return nullptr;
  }

  // One active factor's cost, loss and blocks, written from the graph's problem.
  static bool SaveFactor(SnapshotWriter& w, SGraph::Impl& m, const FactorRecord& f) {
    const ceres::CostFunction* cost = m.problem->GetCostFunctionForResidualBlock(f.id);
    const ceres::LossFunction* loss = m.problem->GetLossFunctionForResidualBlock(f.id);
    LossOf loss_of = LossOf::kNone;
    if (loss == m.huber_relative.get()) loss_of = LossOf::kRelative;
    else if (loss == m.huber_loop.get()) loss_of = LossOf::kLoop;
    else if (loss == m.huber_plane.get()) loss_of = LossOf::kPlane;
    else if (loss == m.huber_room.get()) loss_of = LossOf::kRoom;
    else if (loss != nullptr) return false;
    m.problem->GetParameterBlocksForResidualBlock(f.id, &m.scratch_blocks);
    if (m.scratch_blocks.size() > kMaxBlocks) return false;
    CostOf cost_of{};
    if (dynamic_cast<const sgraph::RelativePoseCost*>(cost) != nullptr) cost_of = CostOf::kRelative;
    else if (dynamic_cast<const sgraph::PlaneCost*>(cost) != nullptr) cost_of = CostOf::kPlane;
    else if (dynamic_cast<const sgraph::RoomCost*>(cost) != nullptr) cost_of = CostOf::kRoom;
    else if (dynamic_cast<const sgraph::CorridorCost*>(cost) != nullptr) cost_of = CostOf::kCorridor;
    else if (dynamic_cast<const sgraph::WallWallCost*>(cost) != nullptr) cost_of = CostOf::kWallWall;
    else if (dynamic_cast<const sgraph::FloorRoomCost*>(cost) != nullptr) cost_of = CostOf::kFloorRoom;
    else if (dynamic_cast<const sgraph::PlanePriorCost*>(cost) != nullptr) cost_of = CostOf::kPlanePrior;
    else return false;
    IoEnum(w, cost_of, kCostKinds);
    IoEnum(w, loss_of, 5);
    auto blocks = static_cast<std::uint8_t>(m.scratch_blocks.size());
    w(blocks);
    for (const double* block : m.scratch_blocks) {
      BlockRef ref;
      if (!Name(m, block, ref)) return false;
      IoEnum(w, ref.of, 6);
      w(ref.index);
    }
    // The functor is copied out (the writer's visitors take what they may also fill).
    switch (cost_of) {
      case CostOf::kRelative: {
        auto z = static_cast<const sgraph::RelativePoseCost*>(cost)->functor();
        Io(w, z);
        break;
      }
      case CostOf::kPlane: {
        auto z = static_cast<const sgraph::PlaneCost*>(cost)->functor();
        Io(w, z);
        break;
      }
      case CostOf::kRoom: {
        auto z = static_cast<const sgraph::RoomCost*>(cost)->functor();
        Io(w, z);
        break;
      }
      case CostOf::kCorridor: {
        auto z = static_cast<const sgraph::CorridorCost*>(cost)->functor();
        Io(w, z);
        break;
      }
      case CostOf::kWallWall: {
        auto z = static_cast<const sgraph::WallWallCost*>(cost)->functor();
        Io(w, z);
        break;
      }
      case CostOf::kFloorRoom: {
        auto z = static_cast<const sgraph::FloorRoomCost*>(cost)->functor();
        Io(w, z);
        break;
      }
      case CostOf::kPlanePrior: {
        auto z = static_cast<const sgraph::PlanePriorCost*>(cost)->functor();
        Io(w, z);
        break;
      }
    }
    return true;
  }

  template <typename Cost, typename Residual>
  static ceres::CostFunction* Make(SnapshotReader& r) {
    Residual z{};
    Io(r, z);
    return new Cost(new Residual(z));
  }

  // What a factor record of its kind must hold: its cost, its loss and the blocks of the nodes
  // it names (a removal finds a factor by its record, and Ceres removes what is on the blocks:
  // the two must agree). False for a record naming nodes beyond the stores.
  static bool Expect(const SGraph::Impl& m, const FactorRecord& f, CostOf cost, LossOf loss,
                     std::array<BlockRef, kMaxBlocks>& want, std::size_t& n) {
    const auto kf = [&](std::uint32_t k) { return k < m.keyframe_high_water; };
    const auto pl = [&](std::uint32_t p) { return p < m.plane_count; };
    const auto add = [&](BlockOf of, std::uint32_t index) { want[n++] = {of, index}; };
    const auto keyframe = [&](std::uint32_t k) {
      add(BlockOf::kKeyframeQ, k);
      add(BlockOf::kKeyframeT, k);
    };
    const auto plane = [&](std::uint32_t p) {
      add(BlockOf::kPlaneN, p);
      add(BlockOf::kPlaneD, p);
    };
    n = 0;
    switch (f.kind) {
      case FactorKind::kRelative:
        if (!kf(f.a) || !kf(f.b) || cost != CostOf::kRelative ||
            loss != (f.relative == RelativePoseKind::kLoopClosure ? LossOf::kLoop : LossOf::kRelative))
          return false;
        keyframe(f.a);
        keyframe(f.b);
        return true;
      case FactorKind::kPlane:
        if (!kf(f.a) || !pl(f.b) || cost != CostOf::kPlane || loss != LossOf::kPlane) return false;
        keyframe(f.a);
        plane(f.b);
        return true;
      case FactorKind::kRoom: {
        if (f.a >= m.room_count || loss != LossOf::kRoom) return false;
        const MapRoom& room = m.rooms[f.a].info;
        const bool four = room.shape == RoomShape::kFourWall;
        if (cost != (four ? CostOf::kRoom : CostOf::kCorridor)) return false;
        add(BlockOf::kRoom, f.a);
        for (int w = 0; w < (four ? 4 : 2); ++w) {
          const std::int32_t wall = room.walls[static_cast<std::size_t>(w)];
          if (wall < 0 || !pl(static_cast<std::uint32_t>(wall))) return false;
          plane(static_cast<std::uint32_t>(wall));
        }
        return true;
      }
      case FactorKind::kWallWall:
        if (!pl(f.a) || !pl(f.b) || cost != CostOf::kWallWall || loss != LossOf::kPlane) return false;
        plane(f.a);
        plane(f.b);
        return true;
      case FactorKind::kFloorRoom:
        if (f.a >= m.room_count || cost != CostOf::kFloorRoom || loss != LossOf::kNone) return false;
        add(BlockOf::kFloor, 0);
        add(BlockOf::kRoom, f.a);
        return true;
      case FactorKind::kPlanePrior:
        if (!pl(f.a) || cost != CostOf::kPlanePrior || loss != LossOf::kPlane) return false;
        plane(f.a);
        return true;
    }
    return false;
  }

  // One factor's residual block, read and added to the loaded graph's problem.
  static bool LoadFactor(SnapshotReader& r, SGraph::Impl& m, std::int32_t slot) {
    CostOf cost_of{};
    LossOf loss_of{};
    std::uint8_t count = 0;
    IoEnum(r, cost_of, kCostKinds);
    IoEnum(r, loss_of, 5);
    r(count);
    if (r.failed() || count > kMaxBlocks) return false;
    std::array<BlockRef, kMaxBlocks> want{};
    std::size_t want_count = 0;
    if (!Expect(m, m.factors[static_cast<std::size_t>(slot)], cost_of, loss_of, want, want_count) ||
        want_count != count)
      return false;
    std::array<double*, kMaxBlocks> blocks{};
    std::array<int, kMaxBlocks> sizes{};
    for (std::size_t i = 0; i < count; ++i) {
      BlockRef ref;
      IoEnum(r, ref.of, 6);
      r(ref.index);
      if (r.failed() || ref.of != want[i].of || ref.index != want[i].index) return false;
      blocks[i] = Resolve(m, ref, sizes[i]);
      if (blocks[i] == nullptr) return false;
    }
    ceres::CostFunction* cost = nullptr;
    switch (cost_of) {
      case CostOf::kRelative: cost = Make<sgraph::RelativePoseCost, sgraph::RelativePoseResidual>(r); break;
      case CostOf::kPlane: cost = Make<sgraph::PlaneCost, sgraph::PlaneResidual>(r); break;
      case CostOf::kRoom: cost = Make<sgraph::RoomCost, sgraph::RoomResidual>(r); break;
      case CostOf::kCorridor: cost = Make<sgraph::CorridorCost, sgraph::CorridorResidual>(r); break;
      case CostOf::kWallWall: cost = Make<sgraph::WallWallCost, sgraph::WallWallResidual>(r); break;
      case CostOf::kFloorRoom: cost = Make<sgraph::FloorRoomCost, sgraph::FloorRoomResidual>(r); break;
      case CostOf::kPlanePrior: cost = Make<sgraph::PlanePriorCost, sgraph::PlanePriorResidual>(r); break;
    }
    // Ceres checks the blocks against the cost's sizes by aborting: checked here first.
    const std::vector<std::int32_t>& expected = cost->parameter_block_sizes();
    bool fits = !r.failed() && expected.size() == count;
    for (std::size_t i = 0; fits && i < count; ++i) fits = expected[i] == sizes[i];
    for (std::size_t i = 0; fits && i < count; ++i)
      for (std::size_t j = 0; j < i; ++j) fits = fits && blocks[i] != blocks[j];
    if (!fits) {
      delete cost;
      return false;
    }
    const ceres::LossFunction* losses[] = {nullptr, m.huber_relative.get(), m.huber_loop.get(),
                                           m.huber_plane.get(), m.huber_room.get()};
    m.Bind(slot, m.problem->AddResidualBlock(
                     cost, const_cast<ceres::LossFunction*>(losses[static_cast<std::size_t>(loss_of)]),
                     blocks.data(), static_cast<int>(count)));
    return true;
  }

  // The records hold together as the graph's own calls leave them (the CRC guards against
  // corruption, this against a snapshot written wrongly or made to pass it): every later call
  // walks these links and counts, so none may point past a store, loop, or disagree with what
  // Ceres holds. Counts are recomputed and compared, not trusted.
  static bool Consistent(const SGraph::Impl& m) {
    const std::size_t kfs = m.keyframe_high_water, factors = m.factor_high_water;
    if (kfs > m.keyframes.size() || m.plane_count > m.planes.size() ||
        m.room_count > m.rooms.size() || factors > m.factors.size())
      return false;
    // The time chain: from the origin by `next` to the newest, every node active, links
    // mutual, stamps rising, and no active keyframe off it.
    std::size_t active = 0;
    for (std::size_t k = 0; k < kfs; ++k) if (m.keyframes[k].active) ++active;
    if (active != m.active_keyframes) return false;
    if (active == 0) {
      if (m.origin != kNone || m.newest != kNone) return false;
    } else {
      const auto in = [&](std::int32_t k) { return k >= 0 && static_cast<std::size_t>(k) < kfs; };
      if (!in(m.origin) || !in(m.newest)) return false;
      std::size_t walked = 0;
      std::int32_t prev = kNone;
      double stamp = -std::numeric_limits<double>::infinity();
      for (std::int32_t k = m.origin; k != kNone; k = m.keyframes[static_cast<std::size_t>(k)].next) {
        if (!in(k) || ++walked > active) return false;
        const KeyframeNode& node = m.keyframes[static_cast<std::size_t>(k)];
        if (!node.active || node.prev != prev || !(node.stamp_s > stamp)) return false;
        prev = k;
        stamp = node.stamp_s;
      }
      if (walked != active || prev != m.newest) return false;
    }
    // Free slots: each once, none in use, and with those in use they make up every slot.
    const auto free_list_ok = [](const std::vector<std::int32_t>& list, std::size_t high_water,
                                 std::size_t in_use, const auto& used) {
      if (list.size() + in_use != high_water) return false;
      for (std::size_t i = 0; i < list.size(); ++i) {
        const std::int32_t s = list[i];
        if (s < 0 || static_cast<std::size_t>(s) >= high_water || used(static_cast<std::size_t>(s)))
          return false;
        for (std::size_t j = 0; j < i; ++j)
          if (list[j] == s) return false;
      }
      return true;
    };
    if (!free_list_ok(m.free_keyframe_slots, kfs, active,
                      [&](std::size_t s) { return m.keyframes[s].active; }))
      return false;
    std::size_t live = 0;
    for (std::size_t s = 0; s < factors; ++s) if (m.factors[s].active) ++live;
    if (live != m.active_factors ||
        !free_list_ok(m.free_factor_slots, factors, live,
                      [&](std::size_t s) { return m.factors[s].active; }))
      return false;
    for (std::int32_t s : m.plane_only_factors)
      if (s < 0 || static_cast<std::size_t>(s) >= factors) return false;
    // Rooms: walls of their shape, and their factors pointing back at them.
    const auto room_factor = [&](std::int32_t f, FactorKind kind, std::size_t room) {
      if (f == kNone) return true;
      if (f < 0 || static_cast<std::size_t>(f) >= factors) return false;
      const FactorRecord& rec = m.factors[static_cast<std::size_t>(f)];
      return rec.active && rec.kind == kind && rec.a == room;
    };
    for (std::size_t i = 0; i < m.room_count; ++i) {
      const RoomNode& r = m.rooms[i];
      if (!room_factor(r.factor, FactorKind::kRoom, i) ||
          !room_factor(r.floor_factor, FactorKind::kFloorRoom, i))
        return false;
      if (!r.in_problem) continue;
      const int walls = r.info.shape == RoomShape::kFourWall ? 4 : 2;
      for (int w = 0; w < walls; ++w) {
        const std::int32_t p = r.info.walls[static_cast<std::size_t>(w)];
        if (p < 0 || static_cast<std::size_t>(p) >= m.plane_count ||
            !m.planes[static_cast<std::size_t>(p)].in_problem)
          return false;
      }
    }
    // Every count a removal decrements, recomputed from the factors.
    std::array<std::size_t, 4> relative{};
    std::size_t plane_factors = 0, room_factors = 0, wall_wall = 0, floor_factors = 0, priors = 0;
    std::vector<std::uint32_t> loops(kfs, 0), observations(m.plane_count, 0);
    for (std::size_t s = 0; s < factors; ++s) {
      const FactorRecord& f = m.factors[s];
      if (!f.active) continue;
      switch (f.kind) {
        case FactorKind::kRelative:
          ++relative[static_cast<std::size_t>(f.relative)];
          if (f.relative == RelativePoseKind::kLoopClosure) {
            ++loops[f.a];
            ++loops[f.b];
          }
          if (!m.keyframes[f.a].active || !m.keyframes[f.b].active) return false;
          break;
        case FactorKind::kPlane:
          ++plane_factors;
          ++observations[f.b];
          if (!m.keyframes[f.a].active) return false;
          break;
        case FactorKind::kRoom:
          ++room_factors;
          if (m.rooms[f.a].factor != static_cast<std::int32_t>(s)) return false;
          break;
        case FactorKind::kWallWall: ++wall_wall; break;
        case FactorKind::kFloorRoom:
          ++floor_factors;
          if (m.rooms[f.a].floor_factor != static_cast<std::int32_t>(s) || !m.floor_active) return false;
          break;
        case FactorKind::kPlanePrior: ++priors; break;
      }
    }
    for (std::size_t k = 0; k < kfs; ++k)
      if (m.keyframes[k].active && m.keyframes[k].loop_factors != loops[k]) return false;
    // Estimates finite, as the graph keeps them (a solve that leaves any non-finite is undone).
    const auto finite = [](const double* v, int n) {
      for (int i = 0; i < n; ++i)
        if (!std::isfinite(v[i])) return false;
      return true;
    };
    for (std::size_t k = 0; k < kfs; ++k) {
      const KeyframeNode& node = m.keyframes[k];
      if (node.active && !(finite(node.q, 4) && finite(node.t, 3))) return false;
    }
    for (std::size_t p = 0; p < m.plane_count; ++p)
      if (m.planes[p].in_problem && !(finite(m.planes[p].n, 3) && finite(m.planes[p].d, 1))) return false;
    for (std::size_t r = 0; r < m.room_count; ++r)
      if (m.rooms[r].in_problem && !finite(m.rooms[r].c, 2)) return false;
    if (m.floor_active && !finite(m.floor_c, 2)) return false;
    for (std::size_t p = 0; p < m.plane_count; ++p)
      if (m.planes[p].info.live_observations != observations[p]) return false;
    const SGraphStats& st = m.stats;
    return st.relative_factors == relative && st.plane_factors == plane_factors &&
           st.room_factors == room_factors && st.wall_wall_factors == wall_wall &&
           st.floor_factors == floor_factors && st.plane_prior_factors == priors;
  }
};

std::size_t SGraph::SnapshotBytes() const {
  const SGraphConfig& c = impl_->config;
  // Generous per record: the fields above, each factor with its most blocks and values.
  constexpr std::size_t kConfig = 256, kScalars = 256 + sizeof(SGraphStats);
  constexpr std::size_t kKeyframe = 8 * (4 + 3 + 1 + 16 + 36) + 4 * 3 + 1;
  constexpr std::size_t kPlane = 8 * (3 + 1 + 3 + 1 + 9 + 3 + 3 + 1 + 16 + 4 + 1 + 1) + 4 * 3 + 3;
  constexpr std::size_t kRoom = 8 * (2 + 2 + 2) + 4 * 6 + 3;
  constexpr std::size_t kFactor = 12 + 3 + kMaxBlocks * 5 + 8 * kMaxValues;
  return kHeaderBytes + kConfig + kScalars + (c.max_keyframes + 1) * (kKeyframe + 4) +
         c.max_planes * kPlane + c.max_rooms * kRoom + c.max_factors * (kFactor + 8) + 3 * 8;
}

Status SGraph::SealSnapshot(std::span<std::uint8_t> snapshot) { return SealSnapshotHeader(snapshot, kMagic); }

Expected<std::size_t> SGraph::Save(std::span<std::uint8_t> out, SnapshotSeal seal) const {
  Impl& m = *impl_;
  if (!m.problem) return Error{Errc::kInvalidArgument, "s-graph not initialised"};
  // A full solve pending would change the graph when it is applied: its snapshot would hold a
  // state the live graph leaves. A job that only borrows the costs (the marginals) reads them
  // on its own problem while this reads the graph's: both only read, and the graph stays.
  if (m.full_job_pending)
    return Error{Errc::kWouldBlock, "a full solve is pending on this graph"};
  if (out.size() < kHeaderBytes) return Error{Errc::kCapacityExceeded, "snapshot buffer too small"};
  SnapshotWriter w(out.subspan(kHeaderBytes));
  SGraphConfig config = m.config;
  Io(w, config);
  SnapshotAccess::IoScalars(w, m);
  for (std::size_t k = 0; k < m.keyframe_high_water; ++k) Io(w, m.keyframes[k]);
  for (std::size_t i = 0; i < m.plane_count; ++i) Io(w, m.planes[i]);
  for (std::size_t i = 0; i < m.room_count; ++i) Io(w, m.rooms[i]);
  for (std::size_t s = 0; s < m.factor_high_water; ++s) {
    Io(w, m.factors[s]);
    if (m.factors[s].active && !SnapshotAccess::SaveFactor(w, m, m.factors[s]))
      return Error{Errc::kInvalidArgument, "s-graph snapshot: a factor the snapshot cannot name"};
  }
  IoList(w, m.free_keyframe_slots, m.keyframes.size());
  IoList(w, m.free_factor_slots, m.factors.size());
  IoList(w, m.plane_only_factors, m.factors.size());
  if (w.failed()) return Error{Errc::kCapacityExceeded, "snapshot buffer too small"};
  return WriteSnapshotHeader(out, kMagic, kVersion, w.size(), seal);
}

Status SGraph::Load(std::span<const std::uint8_t> in) {
  Impl& m = *impl_;
  if (!m.problem) return Error{Errc::kInvalidArgument, "s-graph not initialised"};
  if (m.OldestBorrower() != Impl::kNoBorrower || m.full_job_pending)
    return Error{Errc::kWouldBlock, "a job borrows from this graph"};
  // The header and the whole payload are checked before anything changes.
  auto checked = SnapshotPayload(in, kMagic, kVersion);
  if (!checked) return checked.error();
  const std::span<const std::uint8_t> payload = *checked;
  SnapshotReader r(payload);
  SGraphConfig saved;
  Io(r, saved);
  // The same config, compared as the snapshot writes it.
  std::array<std::uint8_t, 256> a{}, b{};
  SnapshotWriter wa(a), wb(b);
  SGraphConfig now = m.config;
  Io(wa, saved);
  Io(wb, now);
  if (r.failed() || wa.size() != wb.size() || std::memcmp(a.data(), b.data(), wa.size()) != 0)
    return Error{Errc::kInvalidArgument, "s-graph snapshot: made with another graph config"};
  // From here the graph is replaced: any failure leaves it empty (as Init left it). Either
  // way its revision goes past every one it had: it is not the graph a reader saw before.
  const SGraphConfig config = m.config;
  const std::uint64_t revision_before = m.stats.revision;
  if (auto s = Init(config); !s) return s;
  const auto fail = [&](const char* why) -> Status {
    static_cast<void>(Init(config));
    m.stats.revision = revision_before + 1;
    return Error{Errc::kInvalidArgument, why};
  };
  const SGraphStats init_stats = m.stats;
  SnapshotAccess::IoScalars(r, m);
  m.stats.store_bytes = init_stats.store_bytes;
  if (r.failed() || m.keyframe_high_water > m.keyframes.size() || m.plane_count > m.planes.size() ||
      m.room_count > m.rooms.size() || m.factor_high_water > m.factors.size())
    return fail("s-graph snapshot: stores beyond the config's capacities");
  for (std::size_t k = 0; k < m.keyframe_high_water; ++k) Io(r, m.keyframes[k]);
  for (std::size_t i = 0; i < m.plane_count; ++i) Io(r, m.planes[i]);
  for (std::size_t i = 0; i < m.room_count; ++i) Io(r, m.rooms[i]);
  if (r.failed()) return fail("s-graph snapshot: truncated records");
  // The parameter blocks, in slot order, before the factors that name them.
  for (std::size_t k = 0; k < m.keyframe_high_water; ++k) {
    KeyframeNode& node = m.keyframes[k];
    if (!node.active) continue;
    m.problem->AddParameterBlock(node.q, 4, &m.quaternion_manifold);
    m.problem->AddParameterBlock(node.t, 3);
    if (static_cast<std::int32_t>(k) == m.origin) {
      m.problem->SetParameterBlockConstant(node.q);
      m.problem->SetParameterBlockConstant(node.t);
    }
  }
  for (std::size_t i = 0; i < m.plane_count; ++i) {
    if (!m.planes[i].in_problem) continue;
    m.planes[i].in_problem = false;  // EnsurePlaneInProblem adds it
    m.EnsurePlaneInProblem(m.planes[i]);
  }
  for (std::size_t i = 0; i < m.room_count; ++i)
    if (m.rooms[i].in_problem) m.problem->AddParameterBlock(m.rooms[i].c, 2);
  if (m.floor_active) m.problem->AddParameterBlock(m.floor_c, 2);
  for (std::size_t s = 0; s < m.factor_high_water; ++s) {
    Io(r, m.factors[s]);
    if (r.failed()) return fail("s-graph snapshot: truncated factors");
    if (m.factors[s].active && !SnapshotAccess::LoadFactor(r, m, static_cast<std::int32_t>(s)))
      return fail("s-graph snapshot: a factor names no node of the graph");
  }
  IoList(r, m.free_keyframe_slots, m.keyframes.size());
  IoList(r, m.free_factor_slots, m.factors.size());
  IoList(r, m.plane_only_factors, m.factors.size());
  if (r.failed() || r.remaining() != 0) return fail("s-graph snapshot: lists truncated or overlong");
  if (!SnapshotAccess::Consistent(m)) return fail("s-graph snapshot: records that do not hold together");
  if (m.residual_index.size() != m.active_factors)
    return fail("s-graph snapshot: factor count differs from its records");
  m.stats.revision = std::max(m.stats.revision, revision_before) + 1;
  return Ok();
}

}  // namespace msgraphs::core
