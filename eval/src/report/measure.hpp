// report/measure.hpp - what the rows of the report share (measure.cpp), the
// hard section (hard_rows.cpp), the convergence section
// (convergence_rows.cpp) and the Bullet peer row (bullet_row.cpp);
// private to the report engine.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "collide/bodies.hpp"
#include "collide/contacts.hpp"
#include "collide/eval/conservation.hpp"
#include "collide/eval/reference.hpp"
#include "collide/io/scene.hpp"
#include "report.hpp"

namespace collide::report_detail {

// ---------------------------------------------------------------------------
// Error against the reference (measure.cpp).
// ---------------------------------------------------------------------------

/// The long double reference for one error sample.
struct ReferenceResult {
  ImpulseBuffer<long double> impulses;
  std::vector<ReferenceContact<long double>> diagnostics;
  MomentumTotals before, after;  ///< collide/eval/conservation.hpp
};
/// Solves convert_scene<long double>(sample) with reference_solve<long double>,
/// in input order or in `order` (a solve's Schedule::solve_order()).
template <class T>
ReferenceResult reference_of(const Scene<T>& sample, const std::uint32_t* order = nullptr);

/// Fills the error columns of `row` from a variant's impulses and final
/// bodies on the sample, in units of eps (the row's precision).
template <class T>
void fill_error(ReportRow& row, const ImpulseView<const T>& impulses, const BodyView<const T>& after,
                const ReferenceResult& reference, double eps);

// ---------------------------------------------------------------------------
// The hard section (hard_rows.cpp).
// ---------------------------------------------------------------------------

/// Every scene of hard::hard_scene_catalogue() in float and double (float
/// only where the scene is meant for float), fast then accurate, in
/// catalogue order; `progress` is told what runs.
std::vector<HardRow> measure_hard_rows(const ReportOptions& options,
                                       const std::function<void(const std::string&)>& progress);

// ---------------------------------------------------------------------------
// The convergence section (convergence_rows.cpp).
// ---------------------------------------------------------------------------

/// Boxes per side of the convergence section's pile: the largest pile of
/// at most options.convergence_n contacts, at least 2.
std::size_t convergence_pile_side(const ReportOptions& options);
/// The pile, the stack and the debris, each in the input then the colour
/// order: repeat then accumulate at every pass count, then the warm rows;
/// `progress` is told what runs.
std::vector<ConvergenceRow> measure_convergence_rows(const ReportOptions& options,
                                                     const std::function<void(const std::string&)>& progress);

// ---------------------------------------------------------------------------
// The peer (bullet_row.cpp, only with COLLIDE_WITH_BULLET).
// ---------------------------------------------------------------------------

/// "bullet <version>" when the peer is compiled in, "" otherwise.
std::string bullet_version();
/// Measures btSequentialImpulseConstraintSolver on the first `n` contacts of
/// the pairs scene `scene` (frictionless, float), `runs` timed runs, and on
/// the error sample.
ReportRow bullet_row(const Scene<float>& scene, std::size_t n, const Scene<float>& sample,
                     const ReferenceResult& reference, int runs, double triad_bytes_per_second);

}  // namespace collide::report_detail
