// bench/rows.hpp - the bodies of collide_bench's rows: what one row sets up,
// times and reports (rows.cpp). Which rows exist, under which names, is
// registration.cpp's; the scene a row solves is scenes.hpp's.
#pragma once

#include <benchmark/benchmark.h>

#include <cstddef>

#include "collide/isa.hpp"
#include "collide/model.hpp"
#include "collide/solve.hpp"
#include "row_names.hpp"
#include "scenes.hpp"

namespace collide_bench {

/// solve/ and isa/ rows: the rigid model through Solver::solve on `path`.
template <class T>
void solve_row(benchmark::State& state, Kind kind, std::size_t n, collide::Path path, int threads,
               collide::Isa isa = collide::Isa::automatic);

/// model/ and accurate/ rows: one body model on a scene whose bodies fit it,
/// SIMD.
template <class T>
void model_row(benchmark::State& state, Kind kind, std::size_t n, collide::Model model, bool friction, int threads,
               collide::Accuracy accuracy = collide::Accuracy::fast);

/// layout/ rows: one body model on one body layout, SIMD.
template <class T>
void layout_row(benchmark::State& state, Kind kind, std::size_t n, collide::Model model, bool friction, int threads,
                LayoutRow layout);

/// twin/pairs/ rows: the memory-only twin of a model row (memory_twin.hpp).
template <class T>
void twin_row(benchmark::State& state, Kind kind, std::size_t n, collide::Model model, bool friction, int threads);

/// twin/packed/ rows: the packed layout's memory-only twin (packed_twin.hpp).
template <class T>
void packed_twin_row(benchmark::State& state, Kind kind, std::size_t n, collide::Model model, int threads);

/// textbook/ rows: the plain Eigen loop (textbook.hpp), one thread.
template <class T>
void textbook_row(benchmark::State& state, Kind kind, std::size_t n);

/// schedule/ rows: Schedule::build alone, in either order.
template <class T>
void schedule_row(benchmark::State& state, Kind kind, std::size_t n, collide::Order order = collide::Order::input);

/// order/ rows: the rigid model through Solver::solve (SIMD, Isa::automatic)
/// in `order` with `passes` passes; the rate counts every pass's contacts.
/// With `warm` (accumulate only), every solve starts from the J of 64
/// accumulated passes on the same input (SolverOptions::warm_start), copied
/// into the impulse arrays untimed before each solve.
template <class T>
void order_row(benchmark::State& state, Kind kind, std::size_t n, collide::Order order, int passes, int threads,
               collide::Iteration iteration = collide::Iteration::repeat, bool warm = false);
/// order_twin/<scene>/f32/<order>/t:T/n:N: the packed twin walked in that
/// order's schedule (rows.cpp).
template <class T>
void order_twin_row(benchmark::State& state, Kind kind, std::size_t n, collide::Order order, int threads);

}  // namespace collide_bench
