// bench/summary.cpp - the summary collide_bench prints after its run
// (summary.hpp).
//
// Design notes
// ------------
// * Every figure is looked up by its row's name (row_names.hpp) among the
//   rows the reporter kept; a row that did not run (filtered out, --quick, an
//   ISA the CPU lacks) leaves its figure "n/a" or its table line out.
// * With --benchmark_repetitions the summary uses the medians.
// * The summary states figures of this run and their ratios, the ones
//   docs/performance.md and the README's table report; it judges none of
//   them (what a figure should be is for the reader's machine and purpose).
#include "summary.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>
#include <utility>

#include "collide/eval/bandwidth.hpp"
#include "collide/eval/traffic.hpp"
#include "collide/isa.hpp"
#include "collide/model.hpp"
#include "collide/solve.hpp"
#include "row_names.hpp"
#include "scenes.hpp"
#include "support.hpp"

namespace collide_bench {

namespace {

using collide::Path;

/// The precisions of the rows: the tag in their names and the bytes of a
/// value.
struct Precision {
  const char* tag;
  std::size_t bytes;
};
constexpr Precision kPrecisions[] = {{precision_tag<float>(), sizeof(float)},
                                     {precision_tag<double>(), sizeof(double)}};

}  // namespace

void CollectingReporter::ReportRuns(const std::vector<Run>& runs) {
  for (const Run& run : runs) {
    if (run.error_occurred) {
      continue;
    }
    // With repetitions, the median aggregate wins over single repetitions.
    const bool median = run.run_type == Run::RT_Aggregate && run.aggregate_name == "median";
    if (run.run_type == Run::RT_Aggregate && !median) {
      continue;
    }
    const std::string key = row_key(run);
    Result& r = results_[key];
    if (r.valid && !median && had_median_[key]) {
      continue;
    }
    auto counter = [&](const char* name) {
      const auto it = run.counters.find(name);
      return it == run.counters.end() ? 0.0 : it->second.value;
    };
    r = Result{counter("coll/s"), counter("GB/s"), counter("bw_frac"), true, run.report_label};
    if (median) {
      had_median_[key] = true;
      medians_ = true;
    }
  }
  inner_->ReportRuns(runs);
}

std::string CollectingReporter::row_key(const Run& run) {
  std::string name = run.run_name.str();
  const std::string suffix = "/manual_time";
  if (name.size() >= suffix.size() && name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0) {
    name.resize(name.size() - suffix.size());
  }
  return name;
}

void print_summary(const CollectingReporter& rep, const Options& options, bool checks_ok, double load_before,
                   std::ostream& out) {
  char line[512];
  auto print = [&](const char* format, auto... args) {
    std::snprintf(line, sizeof line, format, args...);
    out << line;
  };
  const char* const f32 = precision_tag<float>();

  print("\n==== collide_bench summary (%s) ====\n", rep.medians() ? "medians of the repetitions" : "one run");
  print("load average before/after: %.2f / %.2f on %u CPUs%s\n", load_before, load_average(),
        std::thread::hardware_concurrency(),
        load_before > 0.5 ? " -- other processes were running: expect noisy rows, try --benchmark_repetitions=3" : "");
  print("LLC %zu MiB; triad arrays %zu MiB each\n", llc_bytes() >> 20, collide::default_triad_array_bytes() >> 20);
  print("triad bandwidth: %.2f GB/s at 1 thread, %.2f GB/s at 2 threads\n", triad_gbs(1), triad_gbs(2));
  {
    const char* env = std::getenv("COLLIDE_ISA");
    const std::string isa_auto = env != nullptr && *env != '\0' && std::string(env) != "auto"
                                     ? "COLLIDE_ISA=" + std::string(env)
                                     : "the fastest ISA per kind of solve, measured once per process";
    print("SIMD rows run auto: %s (the widest of this CPU: %s; isa/ rows run each ISA it has, and auto)\n",
          isa_auto.c_str(), collide::to_string(collide::best_isa()));
  }
  if (!checks_ok) {
    print("WARNING: the start-up check failed (see above); the numbers below time a wrong result\n");
  }

  print("\nRatios of this run                                                     measured\n");
  auto figure = [&](const char* what, double value, const char* unit) {
    if (!(value > 0)) {
      print("  %-68s %9s  (rows not run)\n", what, "n/a");
      return;
    }
    print("  %-68s %8.2f%s\n", what, value, unit);
  };
  {
    const Result r = rep.get(solve_name(Kind::pairs, f32, Path::simd, 2, kStreamN));
    figure("pairs f32 simd t:2 n:4Mi, fraction of bandwidth bound", r.bw_frac, "");
  }
  {
    const Result simd = rep.get(solve_name(Kind::pairs, f32, Path::simd, 1, kCacheN));
    const Result scalar = rep.get(solve_name(Kind::pairs, f32, Path::scalar, 1, kCacheN));
    figure("pairs f32 t:1 n:64Ki, simd / scalar", simd.valid && scalar.valid ? simd.coll_per_s / scalar.coll_per_s : 0, "x");
  }
  {
    const Result t2 = rep.get(solve_name(Kind::pairs, f32, Path::simd, 2, kCacheN));
    const Result t1 = rep.get(solve_name(Kind::pairs, f32, Path::simd, 1, kCacheN));
    figure("pairs f32 simd n:64Ki (in LLC), 2 threads / 1 thread",
           t1.valid && t2.valid ? t2.coll_per_s / t1.coll_per_s : 0, "x");
  }
  {
    // The widest ISA against AVX2, in cache and streaming.
    using collide::Isa;
    auto ratio = [&](Kind kind, Isa a, Isa b, int threads, std::size_t n) {
      const Result ra = rep.get(isa_name(kind, f32, a, threads, n));
      const Result rb = rep.get(isa_name(kind, f32, b, threads, n));
      return ra.valid && rb.valid ? ra.coll_per_s / rb.coll_per_s : 0.0;
    };
    if (collide::isa_supported(Isa::avx512)) {
      figure("pairs f32 t:1 n:64Ki, avx512 / avx2", ratio(Kind::pairs, Isa::avx512, Isa::avx2, 1, kCacheN), "x");
      const Result wide = rep.get(isa_name(Kind::pairs, f32, Isa::avx512, 1, kCacheN));
      const Result scalar = rep.get(solve_name(Kind::pairs, f32, Path::scalar, 1, kCacheN));
      figure("pairs f32 t:1 n:64Ki, avx512 / scalar",
             wide.valid && scalar.valid ? wide.coll_per_s / scalar.coll_per_s : 0, "x");
      figure("pairs f32 t:2 n:4Mi, avx512 / avx2", ratio(Kind::pairs, Isa::avx512, Isa::avx2, 2, kStreamN), "x");
      figure("debris f32 t:2 n:4Mi, avx512 / avx2", ratio(Kind::debris, Isa::avx512, Isa::avx2, 2, kStreamN), "x");
    }
    if (collide::isa_supported(Isa::avx2)) {
      figure("pairs f32 t:1 n:64Ki, avx2 / sse2", ratio(Kind::pairs, Isa::avx2, Isa::sse2, 1, kCacheN), "x");
    }
  }
  {
    // Scattered scenes on the packed layout.
    using collide::Model;
    auto per_s = [&](const std::string& name) {
      const Result r = rep.get(name);
      return r.valid ? r.coll_per_s : 0.0;
    };
    auto ratio = [](double a, double b) { return a > 0 && b > 0 ? a / b : 0.0; };
    for (const Model model : {Model::particle, Model::sphere, Model::rigid}) {
      const std::string m = collide::to_string(model);
      const double records = per_s(layout_name(Kind::debris, model, false, f32, LayoutRow::records, 2, kStreamN));
      const double pairs = per_s(model_name(Kind::pairs, model, false, f32, 2, kStreamN));
      const double twin = per_s(packed_twin_name(Kind::debris, model, f32, 2, kStreamN));
      figure(("debris " + m + " f32 t:2 n:4Mi, packed records / pairs").c_str(), ratio(records, pairs), "");
      const std::string vs_twin = "debris " + m + " f32 t:2 n:4Mi, packed records / its memory-only twin";
      if (records > 0 && twin > 0 && records > twin) {
        // A twin slower than the kernel bounds nothing.
        print("  %-68s %8.2f   (the twin runs below the kernel, so it is no ceiling)\n", vs_twin.c_str(),
              ratio(records, twin));
      } else {
        figure(vs_twin.c_str(), ratio(records, twin), "");
      }
      // The twin's own rate against pairs (a ceiling for the line above only
      // where the twin runs faster than the kernel).
      const double twin_vs_pairs = ratio(twin, pairs);
      if (twin_vs_pairs > 0) {
        print("  %-68s %8.2f\n", ("  its twin / " + m + " pairs").c_str(), twin_vs_pairs);
      }
    }
    const double simd = per_s(solve_name(Kind::debris, f32, Path::simd, 2, kStreamN));
    const double scalar = per_s(solve_name(Kind::debris, f32, Path::scalar, 2, kStreamN));
    figure("debris f32 t:2 n:4Mi (SoA input, automatic layout), simd / scalar", ratio(simd, scalar), "x");
  }
  {
    const Result d = rep.get(solve_name(Kind::debris, f32, Path::simd, 2, kStreamN));
    const Result p = rep.get(solve_name(Kind::pairs, f32, Path::simd, 2, kStreamN));
    figure("f32 simd t:2 n:4Mi, debris / pairs throughput", d.valid && p.valid ? d.coll_per_s / p.coll_per_s : 0, "");
    // Piles: every body in about six contacts, so its record can come from
    // cache from one level to the next.
    const std::size_t pile_n = pile_size(kStreamN);
    for (const Kind kind : {Kind::pile, Kind::pile_shuffled}) {
      const Result q = rep.get(solve_name(kind, f32, Path::simd, 2, pile_n));
      const std::string what = std::string("f32 simd t:2 n:4Mi, ") + kind_name(kind) + " / pairs throughput";
      figure(what.c_str(), q.valid && p.valid ? q.coll_per_s / p.coll_per_s : 0, "");
    }
    // The chain: one batch per contact, every contact waiting for the one
    // before, so no lanes or threads across contacts.
    {
      const Result q = rep.get(solve_name(Kind::chain, f32, Path::simd, 2, kStreamN));
      figure("f32 simd t:2 n:4Mi, chain / pairs throughput", q.valid && p.valid ? q.coll_per_s / p.coll_per_s : 0, "");
    }
    // The schedule, which a debris system rebuilds every frame.
    for (const Kind kind : {Kind::pairs, Kind::debris, Kind::pile, Kind::chain}) {
      const std::size_t n = is_pile(kind) ? pile_n : kStreamN;
      const Result s = rep.get(schedule_name(kind, f32, n));
      const std::string what = std::string("schedule ") + kind_name(kind) + " f32 n:4Mi, M contacts/s";
      figure(what.c_str(), s.valid ? s.coll_per_s / 1e6 : 0, "");
    }
  }

  {
    using collide::Model;
    const Result particle = rep.get(model_name(Kind::pairs, Model::particle, false, f32, 2, kStreamN));
    const Result rigid = rep.get(model_name(Kind::pairs, Model::rigid, false, f32, 2, kStreamN));
    figure("pairs f32 t:2 n:4Mi, particle / rigid throughput (no friction)",
           particle.valid && rigid.valid ? particle.coll_per_s / rigid.coll_per_s : 0, "x");
    // The lowest and highest of a figure over the models, with their names.
    struct Range {
      double low = 0, high = 0;
      std::string low_name = "n/a", high_name = "n/a";
      bool any = false;
      void add(double x, const std::string& name) {
        if (!any || x < low) {
          low = x;
          low_name = name;
        }
        if (!any || x > high) {
          high = x;
          high_name = name;
        }
        any = true;
      }
    };
    Range bound_frac, twin_frac, of_twin;
    for (const Model model : {Model::particle, Model::sphere, Model::rigid}) {
      for (const bool friction : {false, true}) {
        const std::string name = model_tag(model, friction);
        const Result r = rep.get(model_name(Kind::pairs, model, friction, f32, 2, kStreamN));
        if (!r.valid) continue;
        bound_frac.add(r.bw_frac, name);
        const Result twin = rep.get(twin_name(model, friction, f32, 2, kStreamN));
        if (twin.valid) {
          twin_frac.add(twin.bw_frac, name);
          of_twin.add(r.coll_per_s / twin.coll_per_s, name);
        }
      }
    }
    figure(("pairs f32 t:2 n:4Mi, lowest model fraction of its bound (" + bound_frac.low_name + ")").c_str(),
           bound_frac.low, "");
    // What the data layout allows (memory_twin.hpp).
    if (of_twin.any) {
      print(
          "  (the models' memory-only twins reach %.2f to %.2f of the bound, and the models\n"
          "   reach %.2f (%s) to %.2f (%s) of their twin's throughput)\n",
          twin_frac.low, twin_frac.high, of_twin.low, of_twin.low_name.c_str(), of_twin.high,
          of_twin.high_name.c_str());
    }
  }

  {
    // auto against the best fixed ISA of the same scene, precision, N and
    // threads: every ISA gives the same bits, so auto is judged on speed only.
    using collide::Isa;
    bool header = false;
    for (Kind kind : {Kind::pairs, Kind::debris}) {
      for (const Precision& precision : kPrecisions) {
        for (const auto& [n, threads] : {std::pair{kCacheN, 1}, std::pair{kStreamN, 2}}) {
          const Result automatic = rep.get(isa_name(kind, precision.tag, Isa::automatic, threads, n));
          Isa best = Isa::automatic;
          Result best_row;
          for (const Isa isa : {Isa::sse2, Isa::avx2, Isa::avx512}) {
            const Result r = rep.get(isa_name(kind, precision.tag, isa, threads, n));
            if (r.valid && (!best_row.valid || r.coll_per_s > best_row.coll_per_s)) {
              best = isa;
              best_row = r;
            }
          }
          if (!automatic.valid || !best_row.valid) continue;
          if (!header) {
            print("\nisa auto against the best fixed ISA (isa/ rows; every ISA gives the same bits)\n");
            print("  %-7s %-4s %3s %9s  %-7s %9s  %-9s %9s  %6s\n", "scene", "prec", "t", "N", "best", "Mcoll/s",
                  "auto ran", "Mcoll/s", "ratio");
            header = true;
          }
          const std::string ran = automatic.label.substr(0, automatic.label.find(','));
          const double r = automatic.coll_per_s / best_row.coll_per_s;
          print("  %-7s %-4s %3d %9zu  %-7s %9.1f  %-9s %9.1f  %6.3f\n", kind_name(kind), precision.tag, threads, n,
                collide::to_string(best), best_row.coll_per_s / 1e6, ran.c_str(), automatic.coll_per_s / 1e6, r);
        }
      }
    }
  }

  // The body models: million collisions per second and fraction of each
  // model's own bandwidth bound, SIMD.
  print(
      "\nBody models, simd [Mcoll/s at 1 / 2 threads; B/coll; bw_frac at 2 threads; the memory-only twin\n"
      "  at 2 threads (pairs): Mcoll/s, its bw_frac, and the model's throughput over the twin's]\n");
  print("  %-7s %-13s %-4s %9s  %8s %8s %6s %7s  %8s %7s %7s\n", "scene", "model", "prec", "N", "t:1", "t:2", "B/coll",
        "bw_frac", "twin t:2", "bw_frac", "of twin");
  for (Kind kind : {Kind::pairs, Kind::debris}) {
    for (const Precision& precision : kPrecisions) {
      for (std::size_t n : options.sizes) {
        for (const collide::Model model : {collide::Model::particle, collide::Model::sphere, collide::Model::rigid}) {
          for (const bool friction : {false, true}) {
            const Result t1 = rep.get(model_name(kind, model, friction, precision.tag, 1, n));
            const Result t2 = rep.get(model_name(kind, model, friction, precision.tag, 2, n));
            if (!t1.valid && !t2.valid) {
              continue;
            }
            const std::size_t bytes = collide::bytes_per_collision(model, precision.bytes, friction);
            const std::string label = std::string(collide::to_string(model)) + (friction ? " + mu" : "");
            print("  %-7s %-13s %-4s %9zu  %8.1f %8.1f %6zu %7.2f", kind_name(kind), label.c_str(), precision.tag, n,
                  t1.coll_per_s / 1e6, t2.coll_per_s / 1e6, bytes, t2.bw_frac);
            const Result twin = rep.get(twin_name(model, friction, precision.tag, 2, n));
            if (kind == Kind::pairs && twin.valid && t2.valid) {
              print("  %8.1f %7.2f %7.2f\n", twin.coll_per_s / 1e6, twin.bw_frac, t2.coll_per_s / twin.coll_per_s);
            } else {
              print("\n");
            }
          }
        }
      }
    }
  }

  // The whole grid in one table: million collisions per second.
  print("\nThroughput [Mcoll/s] (bw_frac of simd/t:2 = its GB/s over the 2-thread triad)\n");
  print("  %-10s %-4s %9s  %9s %9s %9s %9s %9s  %7s\n", "scene", "prec", "N", "scalar/1", "scalar/2", "simd/1",
        "simd/2", "textbook", "bw_frac");
  std::vector<Kind> kinds{Kind::pairs, Kind::debris};
  if (!options.quick) {
    kinds.push_back(Kind::pairs_mu);
  }
  for (Kind kind : kinds) {
    for (const Precision& precision : kPrecisions) {
      for (std::size_t n : options.sizes) {
        const Result rows[5] = {rep.get(solve_name(kind, precision.tag, Path::scalar, 1, n)),
                                rep.get(solve_name(kind, precision.tag, Path::scalar, 2, n)),
                                rep.get(solve_name(kind, precision.tag, Path::simd, 1, n)),
                                rep.get(solve_name(kind, precision.tag, Path::simd, 2, n)),
                                rep.get(textbook_name(kind, precision.tag, n))};
        if (std::none_of(rows, rows + 5, [](const Result& r) { return r.valid; })) {
          continue;
        }
        print("  %-10s %-4s %9zu ", kind_name(kind), precision.tag, n);
        for (const Result& r : rows) {
          if (r.valid) {
            print(" %9.1f", r.coll_per_s / 1e6);
          } else {
            print(" %9s", "-");
          }
        }
        if (rows[3].valid) {
          print("  %7.2f\n", rows[3].bw_frac);
        } else {
          print("  %7s\n", "-");
        }
      }
    }
  }

  print("\nMemory (schedule budget: 16 B/contact + 8 B/body beyond the caller's buffers)\n");
  print("  %-34s %9s %9s %9s %10s %10s %9s %8s\n", "scene", "peak_MiB", "buf_MiB", "bench_MiB", "sched_B/c",
        "sched/bud", "extra_MiB", "xtra/bud");
  for (const MemoryRecord& m : memory_records()) {
    const double budget = 16.0 * static_cast<double>(m.contacts) + 8.0 * static_cast<double>(m.bodies);
    const double mib = 1024.0 * 1024.0;
    print("  %-34s %9.0f %9.0f %9.0f %10.2f %10.2f %9.1f %8.2f%s\n", m.scene.c_str(), m.peak_rss_bytes / mib,
          m.buffer_bytes / mib, m.bench_bytes / mib, m.schedule_bytes / static_cast<double>(m.contacts),
          m.schedule_bytes / budget, m.extra_bytes / mib, m.extra_bytes / budget,
          m.peak_was_reset ? "" : " (peak not resettable)");
  }
  print(
      "  peak = VmHWM after generating, building the schedule and one simd/t:2 solve; buf = bodies + contacts +\n"
      "  impulses; bench = saved velocities and the cache-evict buffer; extra = peak growth over building the\n"
      "  schedule and one solve, i.e. what the kernel costs beyond the caller's buffers.\n");
}

}  // namespace collide_bench
