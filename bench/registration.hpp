// bench/registration.hpp - which rows collide_bench runs, in which order
// (registration.cpp).
#pragma once

#include <cstddef>

#include "options.hpp"

namespace collide_bench {

/// Registers every row with Google Benchmark, in the order they run: the
/// triad first, then the groups of the generated scenes, the group of the
/// --scene file when `file_contacts` > 0 (its N), and the body-model grid.
void register_rows(const Options& options, std::size_t file_contacts);

}  // namespace collide_bench
