// collide/error_bound.hpp - the documented accuracy bound of the kernels.
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

namespace collide {

/// The documented bound on a kernel's impulse error, in units of
/// eps(T) * impulse_scale (see above).
inline constexpr double kImpulseErrorBoundEps = 64.0;

}  // namespace collide
