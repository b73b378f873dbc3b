// bench/row_names.hpp - the names of collide_bench's rows, built in one place
// for registration and for the summary that looks the rows up. Scripts and
// docs parse these names: they are part of the bench's interface.
//
// Every name ends in /t:<threads>/n:<contacts> (schedule rows: /n: only);
// <precision> is precision_tag<T>() ("f32", "f64"), <scene> kind_name(),
// <model> collide::to_string(Model) with "+mu" where friction is drawn.
#pragma once

#include <cstddef>
#include <string>

#include "collide/isa.hpp"
#include "collide/model.hpp"
#include "collide/schedule.hpp"
#include "collide/solve.hpp"
#include "scenes.hpp"

namespace collide_bench {

/// Which body layout a layout row runs.
enum class LayoutRow {
  soa,      ///< the SoA arrays in place (SolverOptions::layout = soa)
  packed,   ///< SoA input that the solver packs, solves and writes back (layout = packed)
  records,  ///< the caller keeps packed records across frames: no packing in the timed solve
};
/// "soa", "packed" or "records".
const char* layout_row_name(LayoutRow layout);

/// The model's part of a name: "rigid", "rigid+mu" with friction.
std::string model_tag(collide::Model model, bool friction);

/// solve/<scene>/<precision>/<scalar|simd>/t:T/n:N
std::string solve_name(Kind kind, const char* precision, collide::Path path, int threads, std::size_t n);
/// isa/<scene>/<precision>/<isa>/t:T/n:N: the SIMD path of one instruction
/// set, or of Isa::automatic ("auto").
std::string isa_name(Kind kind, const char* precision, collide::Isa isa, int threads, std::size_t n);
/// model/<scene>/<model>/<precision>/simd/t:T/n:N
std::string model_name(Kind kind, collide::Model model, bool friction, const char* precision, int threads,
                       std::size_t n);
/// accurate/<scene>/<model>/<precision>/simd/t:T/n:N: a model row in
/// Accuracy::accurate.
std::string accurate_name(Kind kind, collide::Model model, bool friction, const char* precision, int threads,
                          std::size_t n);
/// layout/<scene>/<model>/<precision>/<soa|packed|records>/t:T/n:N
std::string layout_name(Kind kind, collide::Model model, bool friction, const char* precision, LayoutRow layout,
                        int threads, std::size_t n);
/// twin/pairs/<model>/<precision>/t:T/n:N: the memory-only twin of a model
/// row (memory_twin.hpp).
std::string twin_name(collide::Model model, bool friction, const char* precision, int threads, std::size_t n);
/// twin/packed/<scene>/<model>/<precision>/t:T/n:N: the packed layout's
/// memory-only twin (packed_twin.hpp).
std::string packed_twin_name(Kind kind, collide::Model model, const char* precision, int threads, std::size_t n);
/// textbook/<scene>/<precision>/t:1/n:N
std::string textbook_name(Kind kind, const char* precision, std::size_t n);
/// schedule/<scene>/<precision>/n:N
std::string schedule_name(Kind kind, const char* precision, std::size_t n,
                          collide::Order order = collide::Order::input);
/// "order/<scene>/<prec>/<input|colour>/passes:P/t:T/n:N": a solve in that
/// order with P passes per schedule.
std::string order_name(Kind kind, const char* precision, collide::Order order, int passes, int threads, std::size_t n);
/// The iteration modes of an order's passes side by side: per pass, and the
/// residual in the label.
/// A warm-started row has "/warm" after the iteration mode.
std::string iterate_name(Kind kind, const char* precision, collide::Order order, collide::Iteration iteration,
                         int passes, int threads, std::size_t n, bool warm = false);
std::string order_twin_name(Kind kind, const char* precision, collide::Order order, int threads, std::size_t n);

}  // namespace collide_bench
