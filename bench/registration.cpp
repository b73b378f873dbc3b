// bench/registration.cpp - which rows collide_bench registers with Google
// Benchmark, under which names (row_names.hpp), in which order.
//
// Design notes
// ------------
// Google Benchmark runs rows in registration order:
//   triad/t:{1,2}                         memory bandwidth, the bound (triad.cpp)
//   then, for each scene x precision x N, one group:
//     schedule/<scene>/<f32|f64>/n:N      Schedule::build alone
//     solve/<scene>/<prec>/<scalar|simd>/t:{1,2}/n:N
//     isa/<scene>/<prec>/<sse2|avx2|avx512|auto>/t:T/n:N   the SIMD path of
//                                    every ISA the CPU has, and Isa::automatic,
//                                    at 64Ki (t:1) and 4Mi (t:2)
//     textbook/<scene>/<prec>/t:1/n:N     the plain Eigen loop (textbook.hpp), N <= 4Mi
//   then, at 64Ki and 4Mi in float, for pairs, debris, pile, pile+shuffle and chain:
//     schedule/<scene>/f32/colour/n:N     Schedule::build in the colour order
//     order_twin/<scene>/f32/<input|colour>/t:2/n:N   the packed twin
//                                    (packed_twin.hpp) in that order's schedule
//     order/<scene>/f32/<input|colour>/passes:{1,4}/t:{1,2}/n:N   a solve in
//                                    that order; the rate counts every pass
//   then the piles' groups (pile, pile+shuffle) at the largest pile within
//   each target size, and the chain's (float only, at the target sizes: one
//   batch per contact, the law sequential through the row)
//   then the group of the --scene file (scene "file", N its contacts)
//   then the body-model grid at 64Ki and 4Mi, for each (model, friction):
//     model/<scene>/<model>[+mu]/<prec>/simd/t:{1,2}/n:N
//     accurate/<scene>/<model>[+mu]/<prec>/simd/t:{1,2}/n:N   the same, Accuracy::accurate
//     layout/<scene>/<model>[+mu]/<prec>/<soa|packed|records>/t:{1,2}/n:N
//     twin/packed/<scene>/<model>/<prec>/t:{1,2}/n:N   without friction
//     twin/pairs/<model>[+mu]/<prec>/t:{1,2}/n:N   the model's memory-only twin
//                                    (memory_twin.hpp): the ceiling of its layout
// pairs+mu and the chain run at the two target sizes only. A group's rows
// are registered together so that only one scene is alive at a time
// (scenes.hpp).
#include "registration.hpp"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <string>
#include <utility>
#include <vector>

#include "row_names.hpp"
#include "rows.hpp"
#include "scenes.hpp"
#include "support.hpp"

namespace collide_bench {
namespace {

using collide::Path;

/// The textbook baseline runs up to 4Mi: beyond, it is as memory-bound as at
/// 4Mi and costs tens of seconds per row.
constexpr std::size_t kTextbookMaxN = std::size_t{1} << 22;

bool is_target_size(std::size_t n) {
  return n == kCacheN || n == kStreamN || n == pile_size(kCacheN) || n == pile_size(kStreamN);
}

template <class F>
void add_row(const std::string& name, F&& f) {
  benchmark::RegisterBenchmark(name.c_str(), std::forward<F>(f))->UseManualTime()->Unit(benchmark::kMicrosecond);
}

/// Registers one group: every row that shares the scene (kind, T, n).
template <class T>
void register_group(Kind kind, std::size_t n) {
  const char* precision = precision_tag<T>();
  if (kind != Kind::pairs_mu) {
    add_row(schedule_name(kind, precision, n), [=](benchmark::State& s) { schedule_row<T>(s, kind, n); });
  }
  for (Path path : {Path::scalar, Path::simd}) {
    for (int threads : {1, 2}) {
      add_row(solve_name(kind, precision, path, threads, n),
              [=](benchmark::State& s) { solve_row<T>(s, kind, n, path, threads); });
    }
  }
  // The SIMD path of every ISA this CPU has, in cache on 1 thread and
  // streaming on 2, and beside them auto (the rows above run it too): the ISA
  // measured fastest for the kind of solve, which should be within a few
  // percent of the best fixed row.
  if (kind != Kind::pairs_mu && is_target_size(n)) {
    for (const collide::Isa isa :
         {collide::Isa::sse2, collide::Isa::avx2, collide::Isa::avx512, collide::Isa::automatic}) {
      if (!collide::isa_supported(isa)) continue;
      const int threads = n <= kCacheN ? 1 : 2;
      add_row(isa_name(kind, precision, isa, threads, n),
              [=](benchmark::State& s) { solve_row<T>(s, kind, n, Path::simd, threads, isa); });
    }
  }
  if (n <= kTextbookMaxN) {
    add_row(textbook_name(kind, precision, n), [=](benchmark::State& s) { textbook_row<T>(s, kind, n); });
  }
}

/// Registers the body-model grid of one scene and precision: every model with
/// and without friction, SIMD, 1 and 2 threads. Each (model, friction) is its
/// own scene, generated when its first row runs.
template <class T>
void register_models(Kind kind, std::size_t n) {
  const char* precision = precision_tag<T>();
  for (const collide::Model model : {collide::Model::particle, collide::Model::sphere, collide::Model::rigid}) {
    for (const bool friction : {false, true}) {
      for (const int threads : {1, 2}) {
        add_row(model_name(kind, model, friction, precision, threads, n),
                [=](benchmark::State& s) { model_row<T>(s, kind, n, model, friction, threads); });
      }
      // The accurate mode on the same scene: its cost against the
      // rows above.
      for (const int threads : {1, 2}) {
        add_row(accurate_name(kind, model, friction, precision, threads, n), [=](benchmark::State& s) {
          model_row<T>(s, kind, n, model, friction, threads, collide::Accuracy::accurate);
        });
      }
      // Both layouts, on the scene the rows above just used.
      for (const LayoutRow layout : {LayoutRow::soa, LayoutRow::packed, LayoutRow::records}) {
        for (const int threads : {1, 2}) {
          add_row(layout_name(kind, model, friction, precision, layout, threads, n),
                  [=](benchmark::State& s) { layout_row<T>(s, kind, n, model, friction, threads, layout); });
        }
      }
      if (!friction) {
        for (const int threads : {1, 2}) {
          add_row(packed_twin_name(kind, model, precision, threads, n),
                  [=](benchmark::State& s) { packed_twin_row<T>(s, kind, n, model, threads); });
        }
      }
      // The layout's ceiling, on the scene the rows above just used.
      if (kind == Kind::pairs) {
        for (const int threads : {1, 2}) {
          add_row(twin_name(model, friction, precision, threads, n),
                  [=](benchmark::State& s) { twin_row<T>(s, kind, n, model, friction, threads); });
        }
      }
    }
  }
}

}  // namespace

void register_rows(const Options& options, std::size_t file_contacts) {
  register_triad();
  for (Kind kind : {Kind::pairs, Kind::debris, Kind::pairs_mu}) {
    if (kind == Kind::pairs_mu && options.quick) {
      continue;
    }
    for (int precision : {4, 8}) {
      if (precision == 8 && options.quick) {
        continue;
      }
      for (std::size_t n : options.sizes) {
        if (kind == Kind::pairs_mu && !is_target_size(n)) {
          continue;
        }
        if (precision == 4) {
          register_group<float>(kind, n);
        } else {
          register_group<double>(kind, n);
        }
      }
    }
  }

  // The piles, in cell order and shuffled, at the largest pile within each
  // target size (in cache and streaming).
  for (Kind kind : {Kind::pile, Kind::pile_shuffled}) {
    for (int precision : {4, 8}) {
      if (precision == 8 && options.quick) {
        continue;
      }
      for (std::size_t n : options.sizes) {
        if (!is_target_size(n)) {
          continue;
        }
        if (precision == 4) {
          register_group<float>(kind, pile_size(n));
        } else {
          register_group<double>(kind, pile_size(n));
        }
      }
    }
  }

  // The chain, in float at the target sizes: the schedule is one batch per
  // contact, so these rows time the law run sequentially through the chain.
  for (std::size_t n : options.sizes) {
    if (is_target_size(n)) {
      register_group<float>(Kind::chain, n);
    }
  }

  // Both solve orders, with one pass and four per schedule, in float on the
  // scenes with shared bodies and on pairs, at the target sizes: the colour
  // order's rates against the input order's and against pairs. The colour
  // schedule's build beside them.
  for (std::size_t n : options.sizes) {
    if (n != kCacheN && n != kStreamN) continue;
    for (const Kind kind : {Kind::pairs, Kind::debris, Kind::pile, Kind::pile_shuffled, Kind::chain}) {
      const std::size_t size = is_pile(kind) ? pile_size(n) : n;
      add_row(schedule_name(kind, "f32", size, collide::Order::colour),
              [=](benchmark::State& s) { schedule_row<float>(s, kind, size, collide::Order::colour); });
      for (const collide::Order order : {collide::Order::input, collide::Order::colour}) {
        for (const int passes : {1, 4}) {
          for (const int threads : {1, 2}) {
            add_row(order_name(kind, "f32", order, passes, threads, size),
                    [=](benchmark::State& s) { order_row<float>(s, kind, size, order, passes, threads); });
          }
        }
        // Both iteration modes, per pass, on the scenes whose bodies share
        // contacts, on two threads: the accumulated passes' cost against the
        // repeated ones', the residual of each in the label.
        if (kind == Kind::pile || kind == Kind::debris) {
          for (const collide::Iteration iteration : {collide::Iteration::repeat, collide::Iteration::accumulate}) {
            for (const int passes : {1, 4, 16}) {
              add_row(iterate_name(kind, "f32", order, iteration, passes, 2, size),
                      [=](benchmark::State& s) { order_row<float>(s, kind, size, order, passes, 2, iteration); });
            }
          }
          // Warm-started from a converged J of the same input: what a frame
          // loop's resting contacts cost.
          for (const int passes : {1, 2}) {
            add_row(iterate_name(kind, "f32", order, collide::Iteration::accumulate, passes, 2, size, true),
                    [=](benchmark::State& s) {
                      order_row<float>(s, kind, size, order, passes, 2, collide::Iteration::accumulate, true);
                    });
          }
        }
        // The order's memory-only twin: the ceiling of its index pattern.
        add_row(order_twin_name(kind, "f32", order, 2, size),
                [=](benchmark::State& s) { order_twin_row<float>(s, kind, size, order, 2); });
      }
    }
  }

  // The caller's scene, in each precision run, at its own N.
  if (file_contacts > 0) {
    register_group<float>(Kind::file, file_contacts);
    if (!options.quick) register_group<double>(Kind::file, file_contacts);
  }

  // The body-model grid (a scene pays only for what it models) at the
  // two sizes its targets name: in cache and streaming.
  for (Kind kind : {Kind::pairs, Kind::debris, Kind::pile}) {
    for (int precision : {4, 8}) {
      if (precision == 8 && options.quick) {
        continue;
      }
      for (std::size_t n : options.sizes) {
        if (!is_target_size(n)) {
          continue;
        }
        // The pile's grid in float only: the pairs and debris grids already
        // show what double costs.
        if (is_pile(kind) && precision == 8) {
          continue;
        }
        const std::size_t scene_n = is_pile(kind) ? pile_size(n) : n;
        if (precision == 4) {
          register_models<float>(kind, scene_n);
        } else {
          register_models<double>(kind, scene_n);
        }
      }
    }
  }
}

}  // namespace collide_bench
