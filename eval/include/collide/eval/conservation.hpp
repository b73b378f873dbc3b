// collide/eval/conservation.hpp - the conservation figures of a solve:
// linear momentum, angular momentum and kinetic energy of the bodies, and
// how far a solve's totals drift from the reference's.
//
// Design notes
// ------------
// * The law conserves linear and angular momentum exactly between movable
//   bodies (an impulse and its opposite at the same point); immovable bodies
//   absorb what they receive. So a solve is judged against the reference's
//   totals after the same contacts, not against the totals before: the
//   drift is |P - Pref| over the scale of the momenta before, sum m |v|,
//   and likewise |L - Lref| over sum (|p x m v| + |I w|) and |E - Eref| / E
//   (the columns of `collide report`, docs/report.md).
// * Totals are summed in long double over movable bodies (inverse mass 0:
//   no momentum, no energy), the spin as R (I o (R^T w)) with R from the
//   normalised quaternion; a locked axis (inverse moment 0) is left out of
//   the spin terms, since its spin never changes and its moment is infinite.
#pragma once

#include "collide/bodies.hpp"

namespace collide {

/// Linear momentum, angular momentum about the origin (orbital p x m v plus
/// spin), kinetic energy, and the scales the drifts are divided by.
struct MomentumTotals {
  long double p[3] = {0, 0, 0};
  long double l[3] = {0, 0, 0};
  long double energy = 0;
  long double p_scale = 0;  ///< sum m |v|
  long double l_scale = 0;  ///< sum |p x m v| + |I w|
};

/// The totals of `bodies` (T: float, double or long double).
template <class T>
MomentumTotals momentum_totals(const BodyView<const T>& bodies);

/// How far a solve's totals are from the reference's after the same contacts,
/// relative to the scales before them (0 where a scale is 0).
struct ConservationDrift {
  double momentum = 0;          ///< |P - Pref| / sum m|v| (before)
  double angular_momentum = 0;  ///< |L - Lref| / sum (|p x m v| + |I w|) (before)
  double energy = 0;            ///< |E - Eref| / E (before)
};

/// The drift of `after` (a solve's totals) from `reference_after`, both
/// after the same contacts from the state whose totals are `before`.
ConservationDrift conservation_drift(const MomentumTotals& before, const MomentumTotals& reference_after,
                                     const MomentumTotals& after);

}  // namespace collide
