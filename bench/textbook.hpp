// bench/textbook.hpp - the baseline: the loop a user would write from the law.
//
// The loop itself lives in eval/src/report/textbook.hpp, shared with `collide
// report` (its textbook rows), so that the benchmarks and the report measure
// the same baseline. This header keeps the benchmarks' name for it.
#pragma once

#include "../eval/src/report/textbook.hpp"

namespace collide_bench {

using collide::report_detail::textbook_solve;

}  // namespace collide_bench
