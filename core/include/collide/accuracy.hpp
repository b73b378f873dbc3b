// collide/accuracy.hpp - the two accuracy modes of the kernels, and what each
// promises about its error.
//
// Two modes, two promises (docs/collision-law.md, "Error bounds"):
//
//   fast      |J - J_ref| <= kImpulseErrorBoundEps * eps(T) * impulse_scale
//   accurate  |J - J_ref| <= kAccurateErrorUlps * (eps(T) |J_ref| + denorm_min(T))
//
// J_ref is the law evaluated exactly on the kernel's own inputs and
// impulse_scale the contact's speed scale times its apparent mass (both
// computed by the reference, collide/eval/reference.hpp, which also measures
// the errors: collide/eval/error_bound.hpp, collide/eval/check.hpp). The
// constants live in the core because the core's own decisions depend on them:
// a smaller body model may leave out only terms below a quarter of the fast
// bound (collide/model.hpp).
#pragma once

#include <string_view>

namespace collide {

/// How the law's cancellation-prone quantities are evaluated. Both modes
/// compute the same law on the same paths, ISAs and thread counts, and each
/// is bitwise identical across them; they differ from each other in the last
/// bits (docs/collision-law.md, "Accuracy modes").
enum class Accuracy {
  fast,      ///< plain IEEE arithmetic in the working precision
  accurate,  ///< the relative velocity, the lever arms and friction's u' free of cancellation
};

/// "fast" or "accurate".
const char* to_string(Accuracy accuracy);
/// Parses the names of to_string(); throws std::invalid_argument otherwise.
Accuracy parse_accuracy(std::string_view name);

/// The documented bound on a fast-mode impulse error, in units of
/// eps(T) * impulse_scale (plus an underflow floor; collide/eval/error_bound.hpp).
inline constexpr double kImpulseErrorBoundEps = 64.0;

/// What the accurate mode (SolverOptions::accuracy = Accuracy::accurate)
/// promises: the plain relative error of every J within this many ulps of
/// its precision, |J - Jref| <= kAccurateErrorUlps (eps(T) |Jref| +
/// denorm_min(T)), Jref the exact law on the stored inputs
/// (test_hard_accurate and `collide report --hard` check it).
inline constexpr double kAccurateErrorUlps = 8.0;

}  // namespace collide
