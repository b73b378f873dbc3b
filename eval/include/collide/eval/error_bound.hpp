// collide/eval/error_bound.hpp - the unit the kernels' accuracy bound is
// measured in (the bound itself: collide/accuracy.hpp).
//
// A kernel running in precision T (machine epsilon eps) evaluates the law
// with a relative velocity it cannot know better than about eps times the
// speed scale of the contact (see ReferenceContact in reference.hpp). The
// bound is therefore stated against the reference's impulse_scale:
//
//   |J - J_ref| <= kImpulseErrorBoundEps * eps * impulse_scale
//
// for every contact, where J_ref is reference_solve<long double> on exactly
// the kernel's inputs. `collide solve --check` and the tests enforce it.
#pragma once

#include <limits>

#include "collide/accuracy.hpp"
#include "collide/eval/reference.hpp"

namespace collide {

/// The unit an impulse error of a kernel in precision T is measured in:
/// eps(T) * impulse_scale, plus an underflow floor. Below the normal range
/// values keep an absolute spacing of denorm_min(T), so a relative bound
/// cannot hold for subnormal speeds: each of the ~10 operations that form vn
/// may be off by denorm_min / 2, which jn = -(1 + e) vn / K carries through
/// 1/K (with 1 + e <= 2), and J itself rounds to denorm_min.
template <class T, class S>
S impulse_error_unit(const ReferenceContact<S>& d) {
  const S floor = S(std::numeric_limits<T>::denorm_min()) * (S(1) + (d.k_n > S(0) ? S(10) / d.k_n : S(0)));
  return S(std::numeric_limits<T>::epsilon()) * d.impulse_scale + floor;
}

/// |J - J_ref| in units of impulse_error_unit<T>: the figure the bound
/// kImpulseErrorBoundEps applies to (0 when equal, inf when the unit is 0).
template <class T, class S>
S normalised_impulse_error(S error, const ReferenceContact<S>& d) {
  if (error == S(0)) return S(0);
  const S unit = impulse_error_unit<T>(d);
  return unit > S(0) ? error / unit : std::numeric_limits<S>::infinity();
}

}  // namespace collide
