// report/measure.cpp - what the rows of the report share: error against the
// long double reference, momentum and energy totals.
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "collide/eval/conservation.hpp"
#include "collide/eval/error_bound.hpp"
#include "collide/eval/reference.hpp"
#include "collide/io/scene.hpp"
#include "measure.hpp"

namespace collide::report_detail {

namespace {
using L = long double;
}  // namespace

// ---------------------------------------------------------------------------
// Error against the reference.
// ---------------------------------------------------------------------------

template <class T>
ReferenceResult reference_of(const Scene<T>& sample, const std::uint32_t* order) {
  Scene<L> s = convert_scene<L>(sample);
  ReferenceResult r;
  r.before = momentum_totals<L>(std::as_const(s.bodies).view());
  r.impulses.resize(s.contacts.size());
  r.diagnostics.resize(s.contacts.size());
  reference_solve<L>(s.bodies.view(), s.contacts.view(), r.impulses.view(), r.diagnostics.data(),
                     SolveSequence{order, 1});
  r.after = momentum_totals<L>(std::as_const(s.bodies).view());
  return r;
}

template <class T>
void fill_error(ReportRow& row, const ImpulseView<const T>& j, const BodyView<const T>& after,
                const ReferenceResult& reference, double eps) {
  const ImpulseView<const L> ref = reference.impulses.view();
  std::vector<double> errors(j.count);
  double max_err = 0, max_rel = 0;
  for (std::size_t k = 0; k < j.count; ++k) {
    const L dx = L(j.j.x[k]) - ref.j.x[k];
    const L dy = L(j.j.y[k]) - ref.j.y[k];
    const L dz = L(j.j.z[k]) - ref.j.z[k];
    const L dj = std::sqrt(dx * dx + dy * dy + dz * dz);
    double err = static_cast<double>(normalised_impulse_error<T>(dj, reference.diagnostics[k]));
    if (std::isnan(err)) err = std::numeric_limits<double>::infinity();  // a NaN impulse is the worst error
    errors[k] = err;
    max_err = std::max(max_err, err);
    const L jref = std::sqrt(ref.j.x[k] * ref.j.x[k] + ref.j.y[k] * ref.j.y[k] + ref.j.z[k] * ref.j.z[k]);
    if (jref > L(0)) max_rel = std::max(max_rel, static_cast<double>(dj / jref));
  }
  double p99 = 0;
  if (!errors.empty()) {
    // The smallest error that at least 99% of the contacts do not exceed.
    const std::size_t rank = static_cast<std::size_t>(std::ceil(0.99 * static_cast<double>(errors.size()))) - 1;
    std::nth_element(errors.begin(), errors.begin() + static_cast<std::ptrdiff_t>(rank), errors.end());
    p99 = errors[rank];
  }
  row.eps = eps;
  row.max_err_eps = max_err;
  row.p99_err_eps = p99;
  row.max_rel_err = max_rel;

  const ConservationDrift drift = conservation_drift(reference.before, reference.after, momentum_totals<T>(after));
  row.momentum_drift = drift.momentum;
  row.angular_momentum_drift = drift.angular_momentum;
  row.energy_drift = drift.energy;
}

template ReferenceResult reference_of<float>(const Scene<float>&, const std::uint32_t*);
template ReferenceResult reference_of<double>(const Scene<double>&, const std::uint32_t*);
template void fill_error<float>(ReportRow&, const ImpulseView<const float>&, const BodyView<const float>&,
                                const ReferenceResult&, double);
template void fill_error<double>(ReportRow&, const ImpulseView<const double>&, const BodyView<const double>&,
                                 const ReferenceResult&, double);
template void fill_error<L>(ReportRow&, const ImpulseView<const L>&, const BodyView<const L>&, const ReferenceResult&,
                            double);

#ifndef COLLIDE_WITH_BULLET
// Built without Bullet: no peer row (bullet_row.cpp is not compiled).
std::string bullet_version() { return ""; }
ReportRow bullet_row(const Scene<float>&, std::size_t, const Scene<float>&, const ReferenceResult&, int, double) {
  throw std::logic_error("collide was built without Bullet");
}
#endif

}  // namespace collide::report_detail
