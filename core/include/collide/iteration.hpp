// collide/iteration.hpp - how the passes of a solve build J
// (SolverOptions::iteration; docs/collision-law.md, "Iteration").
#pragma once

#include <string_view>

namespace collide {

/// What a pass after the first does (SolverOptions::passes > 1). Both give
/// the same bits with one pass from zero, on every path, ISA, layout, order
/// and thread count; each is bitwise identical across those.
enum class Iteration {
  /// Every pass applies the law to the velocities as they stand, and J is
  /// the sum of the passes' impulses: an impulse once given is never taken
  /// back, and restitution acts in every pass.
  repeat,
  /// Sequential impulses with accumulated totals, as physics engines iterate:
  /// each contact keeps its total normal impulse (clamped at >= 0) and its
  /// total friction impulse (clamped to the Coulomb cone of the normal
  /// total), and every pass moves them towards the target normal velocity,
  /// -e times the contact's approach speed at its first visit, so that
  /// restitution acts once. J is the totals.
  accumulate,
};

/// "repeat" or "accumulate".
const char* to_string(Iteration iteration);
/// Parses the names of to_string(); throws std::invalid_argument otherwise.
Iteration parse_iteration(std::string_view name);

}  // namespace collide
