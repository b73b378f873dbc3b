// collide/eval/reference.hpp - the collision law, written as docs/collision-law.md states it.
//
// This is the yardstick for every fast path: the law of docs/collision-law.md
// evaluated in the world frame with plain 3x3 matrices (Iw^-1 = R diag(1/I) R^T),
// one contact after another in input order (or in a solve's order), in a scalar type S. It is
// instantiated for double, for long double (x87 extended, 64-bit mantissa),
// the reference against which the fast kernels are measured, and for
// __float128 where GCC has it (COLLIDE_HAS_FLOAT128), the one that judges
// the accurate mode in double. It is deliberately plain: no lanes, no schedule, no
// shortcuts.
#pragma once

#include <cstddef>
#include <cstdint>

#include "collide/bodies.hpp"
#include "collide/contacts.hpp"
#include "collide/iteration.hpp"

namespace collide {

/// Per-contact quantities of the reference solve, for error analysis.
template <class S>
struct ReferenceContact {
  S vn = 0;   ///< approach speed u.n before the impulse [m/s] (< 0 approaching)
  S k_n = 0;  ///< K(n), inverse effective mass along n [1/kg]
  S k_t = 0;  ///< K(t) along the friction direction, 0 without friction [1/kg]
  S jn = 0;   ///< normal impulse magnitude [N s]
  S jt = 0;   ///< friction impulse magnitude [N s]
  /// Sum of the magnitudes of the terms of u: |va| + |wa||ra| + |vb| + |wb||rb|
  /// [m/s], plus the velocity uncertainty the two bodies inherit from the
  /// contacts applied to them before in the same pass (Ev + Ew |r| per body;
  /// Ev grows by s / m and Ew by s max(1/I) |r| with every contact on the
  /// body, s that contact's scale from its own speeds, without what it
  /// inherited). The relative velocity is a difference of these terms, so a
  /// kernel in precision eps cannot know u better than about eps *
  /// speed_scale. For a body's first contact of a pass the inherited part is 0.
  S speed_scale = 0;
  /// The impulse scale that the error bound uses [N s]:
  ///   (1 + e) speed_scale / K(n)
  /// for every contact with a movable body (approaching or not), plus, when
  /// friction acts,
  ///   (speed_scale + speed_scale') / K(t) * (1 + |W t| / K(t)),
  /// where speed_scale' is taken after the normal impulse, plus the
  /// uncertainty that impulse leaves in u', s_n |W n| + jn (max(1/Ia) |ra|^2
  /// + max(1/Ib) |rb|^2) with s_n the normal part of the scale, and W is the
  /// contact's compliance (K(d) = d . W d): the friction direction t is a
  /// rounded velocity direction, and K(t) moves with it by up to that factor.
  /// |J| <= impulse_scale for the normal part, and a kernel error of a few
  /// eps * impulse_scale is the best a precision-eps evaluation of the law can
  /// guarantee.
  S impulse_scale = 0;
};

/// The sequence in which a solve applies the law: the contacts in `order`
/// (contact indices, each once: a solve's Schedule::solve_order()), or in input
/// order when it is null; `passes` times over (SolverOptions::passes), J
/// summed over the passes or, with Iteration::accumulate, the totals the
/// passes accumulated (SolverOptions::iteration).
struct SolveSequence {
  const std::uint32_t* order = nullptr;
  std::size_t passes = 1;
  Iteration iteration = Iteration::repeat;
  /// The impulse arrays hold a warm start on entry (SolverOptions::
  /// warm_start; Iteration::accumulate): the first pass starts from it.
  bool warm_start = false;
};

/// Applies the law to every contact in `sequence` (input order by default).
/// Writes J into `impulses` and updates v, w of the bodies. `diagnostics`,
/// when not null, receives one entry per contact: the last pass's, with the
/// impulse scales of all passes added up (J is their sum), each pass's taken
/// as of a one-pass solve from the velocities the pass before left, and,
/// with several passes, widened where a replay of the sequence in the next
/// shorter precision shows the passes amplifying rounding
/// (docs/collision-law.md, "The error bound over passes").
template <class S>
void reference_solve(const BodyView<S>& bodies, const ContactView<S>& contacts, const ImpulseView<S>& impulses,
                     ReferenceContact<S>* diagnostics = nullptr, const SolveSequence& sequence = {});

extern template void reference_solve<double>(const BodyView<double>&, const ContactView<double>&,
                                             const ImpulseView<double>&, ReferenceContact<double>*,
                                             const SolveSequence&);
extern template void reference_solve<long double>(const BodyView<long double>&, const ContactView<long double>&,
                                                  const ImpulseView<long double>&, ReferenceContact<long double>*,
                                                  const SolveSequence&);
#if COLLIDE_HAS_FLOAT128
// The reference's __float128 buffers are instantiated by collide::eval
// (eval/src/quad_buffers.cpp), not by the core.
extern template class BodyBuffer<__float128>;
extern template class ContactBuffer<__float128>;
extern template void reference_solve<__float128>(const BodyView<__float128>&, const ContactView<__float128>&,
                                                 const ImpulseView<__float128>&, ReferenceContact<__float128>*,
                                                 const SolveSequence&);
#endif

/// The same transcription of the law without the error analysis, in the
/// scene's own precision: the obvious loop a user would write from the law
/// (one contact at a time, in input order, world frame; no lanes, schedule
/// or threads). `collide report` and the benchmarks time it as their
/// "textbook" baseline, so that what the kernels buy is measured against the
/// law as written, not against a second transcription of it.
template <class T>
void textbook_solve(const BodyView<T>& bodies, const ContactView<T>& contacts, const ImpulseView<T>& impulses);

extern template void textbook_solve<float>(const BodyView<float>&, const ContactView<float>&,
                                           const ImpulseView<float>&);
extern template void textbook_solve<double>(const BodyView<double>&, const ContactView<double>&,
                                            const ImpulseView<double>&);

}  // namespace collide
