// bench/check.hpp - collide_bench's start-up check: a benchmark of a wrong
// kernel measures nothing useful (check.cpp).
#pragma once

#include <ostream>

namespace collide_bench {

/// On a small scene of every generated kind in float and double: the scalar
/// path on 1 thread and the SIMD path on 2 must agree bitwise, and the SIMD
/// result must be close to the textbook loop's. Writes one line per scene to
/// `out`; false if any check failed.
bool check_kernels(std::ostream& out);

}  // namespace collide_bench
