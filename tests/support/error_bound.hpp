// tests/support/error_bound.hpp - the documented kernel error bound, as the
// tests see it.
//
// The bound is |J - Jref| <= kImpulseErrorBoundEps * eps(T) * impulse_scale
// for every contact (impulse_scale from collide::ReferenceContact). The
// constants belong to the library: the bound to collide/accuracy.hpp (through
// collide/eval/error_bound.hpp), what the fast mode measures within to
// collide/eval/check.hpp.
#pragma once

#include "collide/eval/check.hpp"
#include "collide/eval/error_bound.hpp"

namespace collide::test {
inline constexpr long double kErrorBoundEps = static_cast<long double>(collide::kImpulseErrorBoundEps);
inline constexpr long double kErrorTargetEps = static_cast<long double>(collide::kImpulseErrorTargetEps);
}  // namespace collide::test
