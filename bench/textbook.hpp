// bench/textbook.hpp - the baseline: the loop a user would write from the law.
//
// The loop is collide::textbook_solve (collide/eval/reference.hpp): the
// reference's transcription of the law without its error analysis, in the
// scene's precision, which `collide report` times as its textbook rows too.
// This header keeps the benchmarks' name for it.
#pragma once

#include "collide/eval/reference.hpp"

namespace collide_bench {

using collide::textbook_solve;

}  // namespace collide_bench
