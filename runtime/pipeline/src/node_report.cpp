// SPDX-License-Identifier: MIT
// What a node leaves behind when it stops: its keyframes (TUM), where it placed every other
// robot (origins.csv), and a report on stdout (and in report.txt).
#include <array>
#include <sys/resource.h>

#include <cinttypes>
#include <cstdarg>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "node_impl.hpp"

namespace msgraphs::runtime {

namespace {

void PutPose(std::ostream& out, const Eigen::Isometry3d& T) {
  const Eigen::Quaterniond q(T.linear());
  const Eigen::Vector3d& t = T.translation();
  out << t.x() << ' ' << t.y() << ' ' << t.z() << ' ' << q.x() << ' ' << q.y() << ' ' << q.z()
      << ' ' << q.w();
}

// printf into a growing report; the attribute keeps the format checks.
__attribute__((format(printf, 2, 3))) void Appendf(std::string& text, const char* format, ...) {
  char line[512];
  va_list args;
  va_start(args, format);
  std::vsnprintf(line, sizeof line, format, args);
  va_end(args);
  text += line;
}

std::string Kilobytes(std::uint64_t bytes) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.1f kB", static_cast<double>(bytes) / 1e3);
  return buffer;
}

}  // namespace

void Node::Impl::WriteOutputs() {
  if (config.output_dir.empty()) return;
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(config.output_dir, ec);
  if (ec) {
    std::fprintf(stderr, "msgraphs_node: cannot create %s: %s\n", config.output_dir.c_str(),
                 ec.message().c_str());
    return;
  }
  // Written beside and renamed: a reader never sees half a file.
  auto write = [&](const char* name, auto&& body) {
    const fs::path final_path = fs::path(config.output_dir) / name;
    const fs::path temp = final_path.string() + ".tmp";
    {
      std::ofstream out(temp);
      out.precision(9);
      body(out);
      if (!out) {
        std::fprintf(stderr, "msgraphs_node: cannot write %s\n", temp.c_str());
        return;
      }
    }
    fs::rename(temp, final_path, ec);
  };
  const core::SGraph& graph = mapper.graph();
  write("keyframes.tum", [&](std::ostream& out) {
    out << "# robot " << config.robot.value << " keyframes in its map frame: t x y z qx qy qz qw\n";
    // In time order: sparsification reuses slots, so slot order is not.
    for (std::uint32_t k = graph.FirstKeyframe(); k != core::SGraph::kNoKeyframe;
         k = graph.NextKeyframe(k)) {
      out << std::fixed << graph.keyframe_stamp(k) << ' ';
      out.unsetf(std::ios::fixed);
      PutPose(out, graph.keyframe_pose(k));
      out << '\n';
    }
  });
  std::lock_guard<std::mutex> lock(session_mutex);
  write("origins.csv", [&](std::ostream& out) {
    out << "robot,merged,x,y,z,qx,qy,qz,qw\n";
    for (std::size_t i = 0; i < session.peers(); ++i) {
      const core::CollabPeerStats p = session.peer_stats(i);
      out << p.robot << ',' << (p.merged ? 1 : 0) << ',';
      const Eigen::Isometry3d T = session.T_self_robot(p.robot);
      const Eigen::Quaterniond q(T.linear());
      out << T.translation().x() << ',' << T.translation().y() << ',' << T.translation().z() << ','
          << q.x() << ',' << q.y() << ',' << q.z() << ',' << q.w() << '\n';
    }
  });
}

void Node::Impl::PrintReport() {
  std::string text;
  SlamStatus s;
  {
    std::lock_guard<std::mutex> lock(status_mutex);
    s = slam_status;
  }
  Appendf(text,
          "robot %u report: %" PRIu64 " scans, %" PRIu64
          " keyframes, %u walls, %u rooms distilled\n",
          config.robot.value, s.scans, s.keyframes, s.walls, s.rooms);
  {
    std::lock_guard<std::mutex> lock(session_mutex);
    const core::CollabSessionStats& cs = session.stats();
    for (std::size_t i = 0; i < session.peers(); ++i) {
      const core::CollabPeerStats p = session.peer_stats(i);
      const Eigen::Isometry3d T = session.T_self_robot(p.robot);
      Appendf(text,
              "  robot %u: %s, %zu walls, %zu rooms, %zu matches accepted of %zu; origin (%.2f, "
              "%.2f, %.2f) m\n",
              p.robot, p.merged ? "merged" : "NOT merged", p.walls, p.rooms, p.consistent,
              p.matches, T.translation().x(), T.translation().y(), T.translation().z());
      Appendf(text,
              "    decision: %s; %zu hypotheses (%zu refuted); leader: walls agree along %.1f m "
              "(%.1f m in its weakest direction), %.1f m in conflict with free space; rival: %.1f m%s\n",
              core::ToString(p.verdict), p.hypotheses, p.refuted, p.leader.agreement_m,
              p.leader.constraint_m, p.leader.conflict_m, p.rival.agreement_m,
              p.rival_from_symmetry ? " (a symmetry of one map)" : "");
      Appendf(text,
              "    received: graph %s, descriptors %s, requests %s, clouds %s, free space %s; malformed %" PRIu64
              ", graph gaps %" PRIu64 "\n",
              Kilobytes(p.bytes_received[0]).c_str(), Kilobytes(p.bytes_received[1]).c_str(),
              Kilobytes(p.bytes_received[2]).c_str(), Kilobytes(p.bytes_received[3]).c_str(),
              Kilobytes(p.bytes_received[4]).c_str(),
              p.malformed, p.graph_gaps);
    }
    Appendf(text,
            "  room matches: %" PRIu64 " proposed, %" PRIu64 " rejected by fine alignment, %" PRIu64
            " rejected against the merged estimate, %" PRIu64
            " outside the consistent sets, %" PRIu64 " accepted\n",
            cs.proposals, cs.rejected_fine, cs.rejected_anchored, cs.rejected_consistency,
            cs.accepted);
    Appendf(text,
            "  collab decoders refused %" PRIu64 " messages (malformed, CRC, unknown format)\n",
            cs.malformed);
    Appendf(text, "  sent: graph %s, descriptors %s, requests %s, clouds %s, free space %s\n",
            Kilobytes(cs.bytes_sent[0]).c_str(), Kilobytes(cs.bytes_sent[1]).c_str(),
            Kilobytes(cs.bytes_sent[2]).c_str(), Kilobytes(cs.bytes_sent[3]).c_str(),
            Kilobytes(cs.bytes_sent[4]).c_str());
    Appendf(text,
            "  merge decisions: %" PRIu64 " taken, %" PRIu64 " merges, %" PRIu64 " revised, %" PRIu64
            " undone, %" PRIu64 " logged\n",
            cs.decisions, cs.merges, cs.revised, cs.undone, cs.log_entries);
  }
  const link::LinkStats ls = link->stats();
  std::uint64_t rejected[4] = {};
  std::uint64_t lost = 0, write_failures = 0;
  std::string lost_topics;
  // By topic: the collab message types, then telemetry (link::LinkStats::topics).
  const std::array<const char*, core::kCollabMessageTypes + 1> topic_names = {
      "graph", "descriptors", "requests", "clouds", "free space", "place requests", "place clouds", "telemetry"};
  static_assert(std::tuple_size_v<decltype(link::LinkStats::topics)> == topic_names.size());
  for (std::size_t i = 0; i < ls.topics.size(); ++i) {
    if (ls.topics[i].lost == 0) continue;
    lost_topics += std::string(lost_topics.empty() ? " (" : ", ") + topic_names[i] + " " +
                   std::to_string(ls.topics[i].lost);
  }
  if (!lost_topics.empty()) lost_topics += ")";
  for (const link::TopicStats& t : ls.topics) {
    rejected[0] += t.rejected_version;
    rejected[1] += t.rejected_sender;
    rejected[2] += t.rejected_oversize;
    rejected[3] += t.undecodable;
    lost += t.lost;
    write_failures += t.write_failures;
  }
  Appendf(text,
          "  link: rejected %" PRIu64 " unknown version, %" PRIu64 " bad sender, %" PRIu64
          " oversize, %" PRIu64 " undecodable; %" PRIu64 " lost%s, %" PRIu64
          " write failures; %" PRIu64 " resends for peers, %" PRIu64
          " resync requests; robots appeared %" PRIu64 ", vanished %" PRIu64 "\n",
          rejected[0], rejected[1], rejected[2], rejected[3], lost, lost_topics.c_str(),
          write_failures, resends.load(), resyncs_requested.load(), ls.robots_appeared,
          ls.robots_vanished);
  const auto sq = scans.stats(), oq = odometry.stats();
  Appendf(text,
          "  queues: scans peak %zu/%zu, dropped %" PRIu64
          "; odometry peak %zu/%zu, dropped %" PRIu64 "\n",
          sq.peak, sq.capacity, sq.dropped, oq.peak, oq.capacity, oq.dropped);
  Appendf(text,
          "  latency: keyframe %.1f ms p50, %.1f ms p99; last packet to distilled update on the "
          "wire %.0f ms p50, "
          "%.0f ms p99, %.0f ms max (%" PRIu64 " keyframes)\n",
          s.keyframe_p50_ms, s.keyframe_p99_ms, s.wire_p50_ms, s.wire_p99_ms, s.wire_max_ms,
          s.wire_samples);
  Appendf(text,
          "  threads: SLAM thread's exchanges while mapping %.1f ms p50, %.1f ms p99, %.1f ms max (%" PRIu64
          " tries deferred: the last one not taken yet); collab thread's Match %.1f ms p50, %.1f ms "
          "p99, %.1f ms max\n",
          s.exchange_p50_ms, s.exchange_p99_ms, s.exchange_max_ms, s.exchanges_deferred,
          s.match_p50_ms, s.match_p99_ms, s.match_max_ms);
  Appendf(text,
          "  exchanges held for their walls' marginals (marginals thread): %.1f ms p50, %.1f ms p99, "
          "%.1f ms max (%" PRIu64 " tries found them computing)\n",
          s.marginals_wait_p50_ms, s.marginals_wait_p99_ms, s.marginals_wait_max_ms,
          s.exchanges_awaiting_marginals);
  // Read after the threads ended (the mapper is the SLAM thread's while it runs).
  const core::LocalMapperStats& ms = mapper.stats();
  Appendf(text,
          "  full solves: %" PRIu64 " (lag %zu keyframes), %" PRIu64 " applied from the background, %" PRIu64
          " run by the solver thread, %" PRIu64 " waited for at their keyframe; loop closures %" PRIu64 "\n",
          ms.full_solves, config.mapper.full_solve_lag_keyframes, ms.full_solves_background,
          solver.runs(), ms.full_solves_waited, ms.loop_closures);
  const core::SGraphStats gs = mapper.graph().stats();
  Appendf(text,
          "  graph: %zu keyframes (peak %zu of max_keyframes %zu), %zu sparsified, %" PRIu64
          " removed on request, %" PRIu64 " refused (store full); %zu factors; plane observations of "
          "removed keyframes %zu carried (%zu fused), %zu dropped\n",
          gs.keyframes, gs.keyframes_peak, mapper.graph().config().max_keyframes, gs.sparsified,
          gs.removed_keyframes, gs.rejected_keyframes, gs.factors, gs.sparsify_planes_carried,
          gs.sparsify_planes_fused, gs.sparsify_planes_dropped);
  const core::CollabPublisherStats& ps = publisher.stats();
  Appendf(text,
          "  wall marginals: %" PRIu64 " computed (%" PRIu64 " failed), %" PRIu64
          " by the marginals thread; walls held back to the next exchange (shareable only after "
          "the copy) %" PRIu64 " times; own evidence (solved without peers' priors) %" PRIu64
          " times, %" PRIu64 " not converged, %" PRIu64 " failed; walls / rooms held back for their own "
          "estimates %" PRIu64 " / %" PRIu64 " times; walls no longer observed (sparsified away) held "
          "back %" PRIu64 " times\n",
          ps.marginal_updates, ps.marginal_failures, marginals_solver.runs(),
          ps.walls_awaiting_marginals, ps.own_evidence_jobs, ps.own_solve_unconverged,
          ps.own_solve_failures, ps.walls_awaiting_estimates, ps.rooms_awaiting_estimates,
          ps.walls_unobserved);
  const core::KeyframeCloudStore& store = mapper.clouds();
  const core::KeyframeCloudStoreStats& store_stats = store.stats();
  Appendf(text,
          "  keyframe clouds: %zu stored (%.1f of %.1f M points), places of %.1f m; evicted %" PRIu64
          " whose place kept another cloud, %" PRIu64 " of sparsified keyframes, %" PRIu64
          " that were their place's only one\n",
          store.stored_clouds(), static_cast<double>(store.used_points()) / 1e6,
          static_cast<double>(store.capacity_points()) / 1e6, mapper.cloud_cover().cell_m(),
          store_stats.evicted_covered, store_stats.evicted_gone, store_stats.evicted_uncovered);
  if (checkpoint) {
    const CheckpointStats cs = checkpoint->stats();
    Appendf(text,
            "  checkpoint: generation %" PRIu64 " (newest durable snapshot %" PRIu64 "), %" PRIu64
            " snapshots written this run (last %.1f MB in %.2f s), %" PRIu64 " failed%s%s, %" PRIu64
            " files removed, %" PRIu64 " journal write errors; the %" PRIu64
            " keyframes that took a snapshot %.1f ms p50, %.1f ms max on the SLAM thread\n",
            cs.generation, cs.durable_generation, cs.snapshots_written,
            static_cast<double>(cs.last_snapshot_bytes) / 1e6, cs.last_write_s, cs.snapshot_failures,
            cs.last_failure.empty() ? "" : ": ", cs.last_failure.c_str(), cs.files_removed,
            cs.journal_errors, s.snapshot_keyframes, s.snapshot_keyframe_p50_ms, s.snapshot_keyframe_max_ms);
  }
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  Appendf(text, "  resources: CPU %.1f s user + %.1f s system, peak RSS %.1f MB\n",
          static_cast<double>(usage.ru_utime.tv_sec) +
              static_cast<double>(usage.ru_utime.tv_usec) * 1e-6,
          static_cast<double>(usage.ru_stime.tv_sec) +
              static_cast<double>(usage.ru_stime.tv_usec) * 1e-6,
          static_cast<double>(usage.ru_maxrss) / 1024.0);
  // The same figures for scripts (tools/eval reads them): one "key value" per line.
  std::string stats;
  {
    std::lock_guard<std::mutex> lock(session_mutex);
    const core::CollabSessionStats& cs = session.stats();
    std::uint64_t received[core::kCollabMessageTypes] = {};
    std::size_t merged = 0;
    for (std::size_t i = 0; i < session.peers(); ++i) {
      const core::CollabPeerStats p = session.peer_stats(i);
      for (int k = 0; k < core::kCollabMessageTypes; ++k) received[k] += p.bytes_received[k];
      if (p.merged) ++merged;
    }
    Appendf(stats,
            "robot %u\nscans %" PRIu64 "\nkeyframes %" PRIu64
            "\nwalls %u\nrooms %u\npeers %zu\nmerged %zu\n",
            config.robot.value, s.scans, s.keyframes, s.walls, s.rooms, session.peers(), merged);
    Appendf(stats,
            "matches_proposed %" PRIu64 "\nmatches_rejected_fine %" PRIu64
            "\nmatches_rejected_anchored %" PRIu64 "\nmatches_rejected_consistency %" PRIu64
            "\nmatches_accepted %" PRIu64 "\n",
            cs.proposals, cs.rejected_fine, cs.rejected_anchored, cs.rejected_consistency,
            cs.accepted);
    Appendf(stats, "merge_decisions %" PRIu64 "\nmerges %" PRIu64 "\nmerges_revised %" PRIu64
            "\nmerges_undone %" PRIu64 "\n", cs.decisions, cs.merges, cs.revised, cs.undone);
    const char* kinds[core::kCollabMessageTypes] = {"graph", "descriptors", "requests", "clouds",
                                                   "free_space", "place_requests", "place_clouds"};
    for (int k = 0; k < core::kCollabMessageTypes; ++k) {
      Appendf(stats, "sent_%s_bytes %" PRIu64 "\nreceived_%s_bytes %" PRIu64 "\n", kinds[k],
              cs.bytes_sent[k], kinds[k], received[k]);
    }
  }
  Appendf(stats,
          "keyframe_p50_ms %.2f\nkeyframe_p99_ms %.2f\nwire_p50_ms %.1f\nwire_p99_ms %.1f\n"
          "scan_queue_peak %zu\nscans_dropped %" PRIu64 "\npeak_rss_mb %.1f\n",
          s.keyframe_p50_ms, s.keyframe_p99_ms, s.wire_p50_ms, s.wire_p99_ms, sq.peak, sq.dropped,
          static_cast<double>(usage.ru_maxrss) / 1024.0);
  Appendf(stats,
          "exchange_p50_ms %.2f\nexchange_p99_ms %.2f\nexchange_max_ms %.2f\nexchanges_deferred %" PRIu64
          "\nexchanges_awaiting_marginals %" PRIu64 "\nmarginals_wait_p50_ms %.2f\nmarginals_wait_p99_ms %.2f"
          "\nmarginals_wait_max_ms %.2f"
          "\nmatch_p50_ms %.2f\nmatch_p99_ms %.2f\nmatch_max_ms %.2f\n",
          s.exchange_p50_ms, s.exchange_p99_ms, s.exchange_max_ms, s.exchanges_deferred,
          s.exchanges_awaiting_marginals, s.marginals_wait_p50_ms, s.marginals_wait_p99_ms,
          s.marginals_wait_max_ms, s.match_p50_ms, s.match_p99_ms, s.match_max_ms);
  Appendf(stats,
          "full_solves %" PRIu64 "\nfull_solves_background %" PRIu64 "\nsolver_thread_runs %" PRIu64
          "\nfull_solves_waited %" PRIu64 "\n",
          ms.full_solves, ms.full_solves_background, solver.runs(),
          ms.full_solves_waited);
  Appendf(stats,
          "marginal_updates %" PRIu64 "\nmarginal_failures %" PRIu64 "\nmarginals_thread_runs %" PRIu64
          "\nwalls_awaiting_marginals %" PRIu64 "\nown_evidence_jobs %" PRIu64
          "\nown_solve_unconverged %" PRIu64 "\nown_solve_failures %" PRIu64 "\n",
          ps.marginal_updates, ps.marginal_failures, marginals_solver.runs(),
          ps.walls_awaiting_marginals, ps.own_evidence_jobs, ps.own_solve_unconverged,
          ps.own_solve_failures);
  Appendf(stats,
          "graph_keyframes %zu\ngraph_keyframes_peak %zu\ngraph_sparsified %zu\ngraph_removed %" PRIu64
          "\ngraph_refused %" PRIu64 "\ngraph_factors %zu\ngraph_planes_carried %zu"
          "\ngraph_planes_fused %zu\ngraph_planes_dropped %zu\n",
          gs.keyframes, gs.keyframes_peak, gs.sparsified, gs.removed_keyframes,
          gs.rejected_keyframes, gs.factors, gs.sparsify_planes_carried, gs.sparsify_planes_fused,
          gs.sparsify_planes_dropped);
  Appendf(stats,
          "cloud_store_clouds %zu\ncloud_store_evicted_covered %" PRIu64 "\ncloud_store_evicted_uncovered %" PRIu64
          "\ncloud_cover_cell_m %.2f\n",
          store.stored_clouds(), store_stats.evicted_covered, store_stats.evicted_uncovered,
          mapper.cloud_cover().cell_m());
  std::fputs(text.c_str(), stdout);
  std::fflush(stdout);
  if (!config.output_dir.empty()) {
    std::ofstream out(std::filesystem::path(config.output_dir) / "report.txt");
    out << text;
    std::ofstream stats_out(std::filesystem::path(config.output_dir) / "stats.txt");
    stats_out << stats;
  }
}

}  // namespace msgraphs::runtime
