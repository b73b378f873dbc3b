// collide/eval/check.hpp - what `collide solve --check` and `--stats` compute, for
// every shell: the impulse error of a solve against the long double
// reference (per contact, in eps units) and the statistics record.
//
// Design notes
// ------------
// * The error of contact k is |J_k - Jref_k| / (eps(T) * impulse_scale_k +
//   floor) (normalised_impulse_error in error_bound.hpp), the quantity
//   kImpulseErrorBoundEps bounds. A NaN impulse gives NaN, which the summary
//   counts as the worst error.
// * The statistics record is an ordered list of (key, value), so the CLI's
//   JSON line and the Python dict have the same keys in the same order, from
//   one place.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "collide/accuracy.hpp"
#include "collide/contacts.hpp"
#include "collide/eval/reference.hpp"
#include "collide/solve.hpp"

namespace collide {

/// What the fast mode measures, in units of impulse_error_unit (error_bound.hpp),
/// on every hard family (tests/hard) and every scene of `collide report`,
/// float and double, every model, with and without friction: no contact above
/// this. kImpulseErrorBoundEps (collide/accuracy.hpp) is what is promised; this is what a
/// change must not lose (the tests and `collide report --hard` check it).
inline constexpr double kImpulseErrorTargetEps = 2.0;

/// The normalised error of every contact (eps(T) * impulse_scale units): the
/// kernel's impulses `j` against the reference's `ref`, whose diagnostics are
/// `diag` (one per contact). Requires j.count == ref.count == diag.size().
template <class T>
std::vector<double> impulse_errors_eps(const ImpulseView<const T>& j, const ImpulseView<const long double>& ref,
                                       const std::vector<ReferenceContact<long double>>& diag);

/// The summary `--check` prints.
struct ImpulseCheck {
  double max_error_eps = 0;       ///< max |J - Jref| / (eps * impulse_scale); NaN if an impulse is NaN
  double max_relative_error = 0;  ///< max |J - Jref| / |Jref| over |Jref| > 0
  std::size_t worst_contact = 0;  ///< contact of max_error_eps
  bool passed = true;             ///< max_error_eps <= kImpulseErrorBoundEps
};
template <class T>
ImpulseCheck check_impulses(const ImpulseView<const T>& j, const ImpulseView<const long double>& ref,
                            const std::vector<ReferenceContact<long double>>& diag);

/// Contacts whose impulse is not zero.
template <class T>
std::size_t count_impacts(const ImpulseView<const T>& j);

/// One value of the statistics record.
using StatValue = std::variant<std::uint64_t, double, std::string, bool>;
/// The statistics record: keys in the order they are printed.
using StatRecord = std::vector<std::pair<std::string, StatValue>>;

/// The record of one solve: collisions, impacts, bodies, kernel_seconds,
/// collisions_per_second, precision, threads, model, path, isa, isa_choice,
/// layout, accuracy, lanes, order, passes, batches, largest_batch, colours,
/// overflow_contacts, schedule_seconds, isa_calibration_seconds,
/// allocate_seconds. `kernel_seconds` is the wall time of the solve call
/// given here, less what it may contain that is not the solve's work: the
/// ISA measurement (SolveStats::isa_calibration_seconds) and the allocate
/// phase (SolveStats::allocate_seconds), each reported on its own.
template <class T>
StatRecord solve_record(const SolveStats& stats, const ImpulseView<const T>& impulses, std::size_t bodies,
                        double kernel_seconds, double schedule_seconds);
/// Appends check, max_impulse_error_eps, max_relative_error, worst_contact,
/// error_bound_eps, check_passed, check_seconds.
void add_check(StatRecord& record, const ImpulseCheck& check, double check_seconds);
/// One JSON object on one line (no newline); inf and NaN become null.
std::string to_json(const StatRecord& record);

}  // namespace collide
