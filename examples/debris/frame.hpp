// frame.hpp - one time step of collide_debris: gravity, this step's contacts,
// collide's schedule and solve, the position correction and the integration.
//
// Design notes
// ------------
// * The step owns what lives from step to step but is not the world: the
//   contact arrays, the grid, the Schedule (rebuilt every step, keeping its
//   buffers) and the Solver (one thread pool for the whole run), so that a
//   run is a world and a Frame, stepped.
// * A step returns its figures rather than printing them, so that the run
//   (debris.cpp) decides what to keep and the output (output.cpp) how to
//   show it.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <unordered_map>

#include <collide/schedule.hpp>
#include <collide/solve.hpp>

#include "broadphase.hpp"
#include "options.hpp"
#include "world.hpp"

namespace debris {

/// What one step leaves for the run's figures.
struct StepFigures {
  std::size_t resolved = 0;              // contacts that got an impulse (J != 0) in some pass
  std::size_t warm = 0;                  // contacts warm-started from the last step's J
  double max_depth = 0, mean_depth = 0;  // [m] this step's overlaps, before the position correction
  double lifted = 0;                     // [J] potential energy the position correction added
  double solve_seconds = 0;              // schedule.build and solver.solve
  collide::SolveStats stats;
};

class Frame {
 public:
  Frame(const Options& o, collide::Order order);

  /// Advances the world by one step of o.dt (symplectic Euler).
  StepFigures step(World& world);

  /// The contacts of the last step.
  [[nodiscard]] const Contacts& contacts() const { return contacts_; }
  /// The dependencies the last step's schedule respected.
  [[nodiscard]] std::size_t conflicts() const { return schedule_.conflicts(); }

 private:
  Options options_;
  Contacts contacts_;
  UniformGrid grid_;
  collide::Schedule schedule_;  // rebuilt every step; keeps its buffers
  collide::Solver solver_;      // one thread pool for the whole run
  /// The last step's impulse by pair of bodies (a << 32 | b), for the warm
  /// start: which contact is which across steps is the simulation's to
  /// keep, and here a pair of bodies touches at most once. Kept as engines
  /// keep it, apart from that step's normal: the normal part lambda and the
  /// friction part G = lambda n - J, so that the next step's J is lambda
  /// along its own normal, with G's part in its tangent plane.
  struct LastImpulse {
    Real lambda;
    std::array<Real, 3> friction;
  };
  std::unordered_map<std::uint64_t, LastImpulse> last_j_;
};

}  // namespace debris
