// solve_policy.hpp - what a solve decides before it runs (private to the
// library): the instruction set whose kernel runs, and whether SoA input is
// packed first. Both follow from the scene's shape alone; neither changes a
// bit of the result.
#pragma once

#include <cstddef>

#include "collide/accuracy.hpp"
#include "collide/bodies.hpp"
#include "collide/isa.hpp"
#include "collide/model.hpp"
#include "collide/packed.hpp"
#include "collide/schedule.hpp"
#include "kernel_table.hpp"

namespace collide::detail {

/// How a Solver with `requested` picks its ISA: forced (a named ISA),
/// environment (automatic and COLLIDE_ISA names one; "auto" there is the same
/// as unset) or measured per solve.
IsaChoice isa_choice_for(Isa requested);

/// The table of a fixed choice (resolve_isa checks the CPU and reads
/// COLLIDE_ISA, throwing for an unknown or unsupported ISA); none when the
/// choice is measured per solve.
const KernelTable* fixed_kernels(Isa requested, IsaChoice choice);

/// The kernels of one solve and how they were chosen.
struct IsaPick {
  const KernelTable* kernels;
  IsaChoice choice;
  double calibration_seconds;  ///< spent measuring by this solve (SolveStats::isa_calibration_seconds)
};

/// The ISA of a solve of `model` in T on `path` in `accuracy` (the
/// SolverOptions'): the fixed one, or the fastest for the solve's kind
/// (measured on first use; scattered when most of its contacts are,
/// scattered_contacts). The scalar path runs the baseline's one-lane kernel
/// whatever the choice, and measures nothing.
template <class T>
IsaPick pick_isa(Path path, Accuracy accuracy, IsaChoice choice, const KernelTable* fixed, Model model,
                 std::size_t scattered, std::size_t contacts);

/// Contacts of the schedule that reach their bodies at random: those of
/// batches that are not consecutive contacts, and those of consecutive
/// batches whose bodies, sampled, do not follow one another.
std::size_t scattered_contacts(const Schedule& schedule, const BodyIndex* a, const BodyIndex* b);

/// Whether a solve over `schedule` copies its contacts into the schedule's
/// order first (prepared_contacts.hpp): in the colour order, when a batch is
/// not consecutive contacts of the input. (A colour order of consecutive
/// batches, pairs', reads the caller's arrays as they are.)
bool prepares_contacts(const Schedule& schedule);

/// Whether a solve on prepared contacts forms the velocity-free half of the
/// law once, with the copy, and takes the velocity step alone in every pass
/// (prepared_contacts.hpp): with several passes, in the fast mode, without
/// friction. (The Coulomb step's lever arms lie along the sliding
/// direction, which the velocities decide; the accurate mode forms its
/// geometry in wider lanes than it could store.)
bool steps_prepared_contacts(std::size_t passes, bool accurate, bool friction);

/// Whether SoA input of `bodies` bodies, `scattered` of whose contacts reach
/// them at random, is packed (BodyLayout::automatic), or what `layout` forces.
bool should_pack(BodyLayout layout, std::size_t scattered, std::size_t bodies);

}  // namespace collide::detail
