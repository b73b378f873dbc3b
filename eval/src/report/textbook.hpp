// report/textbook.hpp - the baseline: the loop a user would write from the law.
//
// Design notes
// ------------
// One contact at a time, in input order, with Eigen's fixed-size Vector3,
// Matrix3 and Quaternion, in the world frame: the inverse inertia of each body
// is rebuilt as Iw^-1 = R diag(1/I) R^T for every contact, K(d) is evaluated
// with it, and the impulse is applied with it. No lanes, no schedule, no
// threads, no precomputation: this row answers "what does the library buy me
// over the obvious code". It reads the same structure-of-arrays buffers as the
// kernel (a user of the library has those), so the rows differ only in the
// arithmetic and its organisation.
//
// It follows collision-law.md line by line, including friction when the view
// carries mu, so it also serves as a cross-check of the kernel at start-up
// (results agree to rounding, not bitwise: the operation order differs).
//
// Shared by `collide report` (its "textbook" rows) and the benchmarks
// (bench/), so both measure the same baseline. Private: not installed.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstddef>

#include "collide/bodies.hpp"
#include "collide/contacts.hpp"

namespace collide::report_detail {

template <class T>
void textbook_solve(const collide::BodyView<T>& bodies, const collide::ContactView<T>& contacts,
                    const collide::ImpulseView<T>& impulses) {
  using V3 = Eigen::Matrix<T, 3, 1>;
  using M3 = Eigen::Matrix<T, 3, 3>;
  struct Body {
    T inv_mass;
    M3 inv_inertia_world;
    V3 p, v, w;
  };
  auto load = [&](std::size_t i) {
    const Eigen::Quaternion<T> q(bodies.q.w[i], bodies.q.x[i], bodies.q.y[i], bodies.q.z[i]);
    const M3 r = q.toRotationMatrix();
    const V3 inv_i(bodies.inv_inertia.x[i], bodies.inv_inertia.y[i], bodies.inv_inertia.z[i]);
    return Body{bodies.inv_mass[i], r * inv_i.asDiagonal() * r.transpose(),
                V3(bodies.p.x[i], bodies.p.y[i], bodies.p.z[i]), V3(bodies.v.x[i], bodies.v.y[i], bodies.v.z[i]),
                V3(bodies.w.x[i], bodies.w.y[i], bodies.w.z[i])};
  };
  auto store = [&](std::size_t i, const Body& body) {
    bodies.v.x[i] = body.v.x();
    bodies.v.y[i] = body.v.y();
    bodies.v.z[i] = body.v.z();
    bodies.w.x[i] = body.w.x();
    bodies.w.y[i] = body.w.y();
    bodies.w.z[i] = body.w.z();
  };

  for (std::size_t k = 0; k < contacts.count; ++k) {
    const std::size_t ia = contacts.a[k], ib = contacts.b[k];
    Body a = load(ia), b = load(ib);
    const V3 c(contacts.c.x[k], contacts.c.y[k], contacts.c.z[k]);
    const V3 n(contacts.n.x[k], contacts.n.y[k], contacts.n.z[k]);
    const V3 ra = c - a.p, rb = c - b.p;
    auto relative_velocity = [&] { return V3((a.v + a.w.cross(ra)) - (b.v + b.w.cross(rb))); };
    auto k_of = [&](const V3& d) {
      const V3 rad = ra.cross(d), rbd = rb.cross(d);
      return a.inv_mass + b.inv_mass + rad.dot(a.inv_inertia_world * rad) + rbd.dot(b.inv_inertia_world * rbd);
    };
    auto apply = [&](const V3& impulse) {
      a.v += impulse * a.inv_mass;
      a.w += a.inv_inertia_world * ra.cross(impulse);
      b.v -= impulse * b.inv_mass;
      b.w -= b.inv_inertia_world * rb.cross(impulse);
    };

    V3 j = V3::Zero();
    const T vn = relative_velocity().dot(n);
    const T kn = vn < T(0) ? k_of(n) : T(0);  // K only for an approaching contact
    if (kn != T(0)) {
      const T e = contacts.e ? contacts.e[k] : contacts.uniform_e;
      const T jn = -(T(1) + e) * vn / kn;
      apply(jn * n);
      j = jn * n;
      const T mu = contacts.mu ? contacts.mu[k] : T(0);
      if (mu > T(0)) {
        const V3 u = relative_velocity();
        const V3 ut = u - u.dot(n) * n;
        const T ut_norm = ut.norm();
        if (ut_norm > T(0)) {
          const V3 t = ut / ut_norm;
          const T jt = std::min(ut_norm / k_of(t), mu * jn);
          apply(-jt * t);
          j -= jt * t;
        }
      }
      store(ia, a);
      store(ib, b);
    }
    impulses.j.x[k] = j.x();
    impulses.j.y[k] = j.y();
    impulses.j.z[k] = j.z();
  }
}

}  // namespace collide::report_detail
