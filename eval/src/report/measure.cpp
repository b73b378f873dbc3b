// report/measure.cpp - what the rows of the report share: error against the
// long double reference, momentum and energy totals, the median of run times.
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

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

double median(std::vector<double> values) {
  if (values.empty()) return 0;
  const auto mid = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), mid, values.end());
  if (values.size() % 2 == 1) return *mid;
  return 0.5 * (*mid + *std::max_element(values.begin(), mid));
}

template <class T>
Totals body_totals(const BodyView<const T>& b) {
  Totals t;
  for (std::size_t i = 0; i < b.count; ++i) {
    if (b.inv_mass[i] == T(0)) continue;  // immovable: no momentum, no energy
    const L m = L(1) / L(b.inv_mass[i]);
    const L p[3] = {L(b.p.x[i]), L(b.p.y[i]), L(b.p.z[i])};
    const L v[3] = {L(b.v.x[i]), L(b.v.y[i]), L(b.v.z[i])};
    const L w[3] = {L(b.w.x[i]), L(b.w.y[i]), L(b.w.z[i])};
    // Orbital part p x m v.
    const L orbital[3] = {m * (p[1] * v[2] - p[2] * v[1]), m * (p[2] * v[0] - p[0] * v[2]),
                          m * (p[0] * v[1] - p[1] * v[0])};
    // Spin part R (I o (R^T w)), with R from the normalised quaternion.
    L qw = L(b.q.w[i]), qx = L(b.q.x[i]), qy = L(b.q.y[i]), qz = L(b.q.z[i]);
    const L qn = std::sqrt(qw * qw + qx * qx + qy * qy + qz * qz);
    qw /= qn, qx /= qn, qy /= qn, qz /= qn;
    const L r[3][3] = {{1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qw * qz), 2 * (qx * qz + qw * qy)},
                       {2 * (qx * qy + qw * qz), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - qw * qx)},
                       {2 * (qx * qz - qw * qy), 2 * (qy * qz + qw * qx), 1 - 2 * (qx * qx + qy * qy)}};
    const L inv_i[3] = {L(b.inv_inertia.x[i]), L(b.inv_inertia.y[i]), L(b.inv_inertia.z[i])};
    L spin_body[3], spin[3] = {0, 0, 0}, spin_energy = 0;
    for (int k = 0; k < 3; ++k) {
      const L wb = r[0][k] * w[0] + r[1][k] * w[1] + r[2][k] * w[2];  // (R^T w)_k
      // A locked axis (inverse moment 0) never changes its spin: left out.
      spin_body[k] = inv_i[k] > 0 ? wb / inv_i[k] : L(0);
      spin_energy += inv_i[k] > 0 ? wb * wb / inv_i[k] : L(0);
    }
    for (int row = 0; row < 3; ++row) {
      for (int k = 0; k < 3; ++k) spin[row] += r[row][k] * spin_body[k];
    }
    const L v2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
    for (int k = 0; k < 3; ++k) {
      t.p[k] += m * v[k];
      t.l[k] += orbital[k] + spin[k];
    }
    t.energy += L(0.5) * (m * v2 + spin_energy);
    t.p_scale += m * std::sqrt(v2);
    t.l_scale += std::sqrt(orbital[0] * orbital[0] + orbital[1] * orbital[1] + orbital[2] * orbital[2]) +
                 std::sqrt(spin[0] * spin[0] + spin[1] * spin[1] + spin[2] * spin[2]);
  }
  return t;
}

template <class T>
ReferenceResult reference_of(const Scene<T>& sample) {
  Scene<L> s = convert_scene<L>(sample);
  ReferenceResult r;
  r.before = body_totals<L>(std::as_const(s.bodies).view());
  r.impulses.resize(s.contacts.size());
  r.diagnostics.resize(s.contacts.size());
  reference_solve<L>(s.bodies.view(), s.contacts.view(), r.impulses.view(), r.diagnostics.data());
  r.after = body_totals<L>(std::as_const(s.bodies).view());
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

  const Totals t = body_totals<T>(after);
  const Totals& r = reference.after;
  auto distance = [](const L* a, const L* b) {
    return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
  };
  const Totals& before = reference.before;
  row.momentum_drift = before.p_scale > 0 ? static_cast<double>(distance(t.p, r.p) / before.p_scale) : 0;
  row.angular_momentum_drift = before.l_scale > 0 ? static_cast<double>(distance(t.l, r.l) / before.l_scale) : 0;
  row.energy_drift = before.energy > 0 ? static_cast<double>(std::fabs(t.energy - r.energy) / before.energy) : 0;
}

template Totals body_totals<float>(const BodyView<const float>&);
template Totals body_totals<double>(const BodyView<const double>&);
template Totals body_totals<L>(const BodyView<const L>&);
template ReferenceResult reference_of<float>(const Scene<float>&);
template ReferenceResult reference_of<double>(const Scene<double>&);
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
