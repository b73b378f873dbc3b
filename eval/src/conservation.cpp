// conservation.cpp - the totals and drifts of collide/eval/conservation.hpp.
#include "collide/eval/conservation.hpp"

#include <cmath>

namespace collide {
namespace {
using L = long double;
}  // namespace

template <class T>
MomentumTotals momentum_totals(const BodyView<const T>& b) {
  MomentumTotals t;
  for (std::size_t i = 0; i < b.count; ++i) {
    if (is_immovable(b, i)) continue;  // no momentum, no energy
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

ConservationDrift conservation_drift(const MomentumTotals& before, const MomentumTotals& reference_after,
                                     const MomentumTotals& after) {
  const auto distance = [](const L* a, const L* b) {
    return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
  };
  const MomentumTotals& r = reference_after;
  ConservationDrift d;
  d.momentum = before.p_scale > 0 ? static_cast<double>(distance(after.p, r.p) / before.p_scale) : 0;
  d.angular_momentum = before.l_scale > 0 ? static_cast<double>(distance(after.l, r.l) / before.l_scale) : 0;
  d.energy = before.energy > 0 ? static_cast<double>(std::fabs(after.energy - r.energy) / before.energy) : 0;
  return d;
}

template MomentumTotals momentum_totals<float>(const BodyView<const float>&);
template MomentumTotals momentum_totals<double>(const BodyView<const double>&);
template MomentumTotals momentum_totals<long double>(const BodyView<const long double>&);

}  // namespace collide
