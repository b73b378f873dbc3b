// hard_attribution.cpp - where the fast mode's impulse error comes from, per
// hard family and per term of the law (issue 13, item 1).
//
// Usage: hard_attribution [count]   (built with the tests, run by hand)
//
// Method. For one contact the law is a chain of terms, each evaluated by the
// fast kernel in its own precision T in a fixed order (contact_kernel.hpp):
//   n      the stored normal taken as unit (the law normalises it)
//   u      relative velocity (va + wa x ra) - (vb + wb x rb), ra = c - pa
//   vn     u . n
//   lever  h = R^T (r x n) as the kernel forms it (float: in double from q
//          normalised, then rounded; double: R from the stored q), invI o h,
//          h . invI o h
//   K      1/ma + 1/mb + ka + kb
//   div    jn = -((1 + e) vn) / K, and J = jn n
//   apply  v += n jn / m, w += R (invI o h) jn
//   fric   u' after the normal impulse, ut, |ut|, t, K(t), jt = min(|ut|/K(t), mu jn)
// This tool evaluates that chain in __float128 with the inputs exactly as
// stored, except for ONE term which it evaluates as the kernel does, in T
// (inputs rounded to T, T operations in the kernel's order, result widened):
// the error of J that follows is what that term alone injects. "all" runs
// every term in T (the fast kernel's arithmetic, rigid model) and "kernel" is
// the real kernel (Solver, fast mode, rigid) for comparison. Errors are in
// the law's unit, eps(T) times the impulse scale of reference_solve<__float128>
// (impulse_error_unit in collide/error_bound.hpp), max over the family.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <type_traits>
#include <vector>

#include "collide/error_bound.hpp"
#include "collide/reference.hpp"
#include "collide/schedule.hpp"
#include "collide/solve.hpp"
#include "hard/hard_families.hpp"

namespace collide::hard {
namespace {

using Q = __float128;

enum Term { kN, kU, kVn, kLever, kK, kDiv, kApply, kFric, kTerms };
const char* const kTermNames[kTerms] = {"n", "u", "vn", "lever", "K", "div", "apply", "fric"};

Q qsqrt(Q x) {
  if (x == 0) return 0;
  Q y = static_cast<Q>(std::sqrt(static_cast<long double>(x)));
  y = (y + x / y) / 2;
  return (y + x / y) / 2;
}
double qsqrt(double x) { return std::sqrt(x); }
float qsqrt(float x) { return std::sqrt(x); }

template <class X>
struct V3 {
  X x, y, z;
};
template <class X>
V3<X> operator+(V3<X> a, V3<X> b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
template <class X>
V3<X> operator-(V3<X> a, V3<X> b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
template <class X>
V3<X> operator*(V3<X> a, X s) {
  return {a.x * s, a.y * s, a.z * s};
}
template <class X>
X dot(V3<X> a, V3<X> b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
template <class X>
V3<X> cross(V3<X> a, V3<X> b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <class X>
V3<X> had(V3<X> a, V3<X> b) {
  return {a.x * b.x, a.y * b.y, a.z * b.z};
}
template <class Y, class X>
V3<Y> as(V3<X> a) {
  return {static_cast<Y>(a.x), static_cast<Y>(a.y), static_cast<Y>(a.z)};
}

/// One body as stored, widened to Q.
struct Body {
  Q inv_mass;
  V3<Q> inv_i, p, v, w;
  Q q[4];
};

/// R (row-major) from q: in T as the fast kernel does (q taken as unit), in
/// Q normalised as the law says.
template <class X>
struct Rot {
  X r[3][3];
};
template <class X>
Rot<X> rotation_of(const Q qq[4], bool normalise) {
  X w = static_cast<X>(qq[0]), x = static_cast<X>(qq[1]), y = static_cast<X>(qq[2]), z = static_cast<X>(qq[3]);
  X s = 2;
  if (normalise) s = X(2) / (w * w + x * x + y * y + z * z);
  Rot<X> m;
  m.r[0][0] = X(1) - s * (y * y + z * z);
  m.r[0][1] = s * (x * y - w * z);
  m.r[0][2] = s * (x * z + w * y);
  m.r[1][0] = s * (x * y + w * z);
  m.r[1][1] = X(1) - s * (x * x + z * z);
  m.r[1][2] = s * (y * z - w * x);
  m.r[2][0] = s * (x * z - w * y);
  m.r[2][1] = s * (y * z + w * x);
  m.r[2][2] = X(1) - s * (x * x + y * y);
  return m;
}
template <class X>
V3<X> to_body(const Rot<X>& m, V3<X> v) {
  return {m.r[0][0] * v.x + m.r[1][0] * v.y + m.r[2][0] * v.z, m.r[0][1] * v.x + m.r[1][1] * v.y + m.r[2][1] * v.z,
          m.r[0][2] * v.x + m.r[1][2] * v.y + m.r[2][2] * v.z};
}
template <class X>
V3<X> to_world(const Rot<X>& m, V3<X> v) {
  return {m.r[0][0] * v.x + m.r[0][1] * v.y + m.r[0][2] * v.z, m.r[1][0] * v.x + m.r[1][1] * v.y + m.r[1][2] * v.z,
          m.r[2][0] * v.x + m.r[2][1] * v.y + m.r[2][2] * v.z};
}

/// h = R^T (r x d) as the fast kernel forms it from the stored values: the
/// rigid float kernel in double lanes, from q normalised, rounded once to
/// float (contact_kernel.hpp, wide_lever); the double kernel in double with
/// R from q taken as unit.
template <class T>
V3<T> kernel_lever(const Body& x, V3<Q> c, V3<Q> d) {
  if constexpr (std::is_same_v<T, float>) {
    const V3<double> r = as<double>(as<T>(c)) - as<double>(as<T>(x.p));
    const V3<double> xd = cross(r, as<double>(as<T>(d)));
    const double qw = static_cast<T>(x.q[0]);
    const V3<double> qv{static_cast<T>(x.q[1]), static_cast<T>(x.q[2]), static_cast<T>(x.q[3])};
    const double s = 2.0 / (((qw * qw + qv.x * qv.x) + qv.y * qv.y) + qv.z * qv.z);
    const V3<double> qx = cross(qv, xd);
    return as<T>(xd + (cross(qv, qx) - qx * qw) * s);
  } else {
    return to_body(rotation_of<T>(x.q, false), cross(as<T>(c) - as<T>(x.p), as<T>(d)));
  }
}

/// The law on one contact with term `in_t` evaluated in T (kTerms: none;
/// -1: all). Returns J in Q.
template <class T>
V3<Q> law(Body a, Body b, V3<Q> c, V3<Q> n_stored, Q e, Q mu, int in_t) {
  auto t_term = [&](int term) { return in_t < 0 || in_t == term; };
  // n: the law normalises; the fast kernel uses the stored n as it is.
  const V3<Q> n = t_term(kN) ? n_stored : n_stored * (Q(1) / qsqrt(dot(n_stored, n_stored)));
  auto velocity = [&](const Body& a_, const Body& b_, bool in_T) {
    if (in_T) {
      const V3<T> ra = as<T>(c) - as<T>(a_.p), rb = as<T>(c) - as<T>(b_.p);
      return as<Q>((as<T>(a_.v) + cross(as<T>(a_.w), ra)) - (as<T>(b_.v) + cross(as<T>(b_.w), rb)));
    }
    const V3<Q> ra = c - a_.p, rb = c - b_.p;
    return (a_.v + cross(a_.w, ra)) - (b_.v + cross(b_.w, rb));
  };
  struct Arm {
    V3<Q> response;
    Q k;
  };
  auto arm = [&](const Body& x, V3<Q> d, bool in_T) {
    if (x.inv_mass == 0) return Arm{{0, 0, 0}, 0};
    if (in_T) {
      const Rot<T> R = rotation_of<T>(x.q, false);
      const V3<T> h = kernel_lever<T>(x, c, d);
      const V3<T> resp = had(as<T>(x.inv_i), h);
      return Arm{as<Q>(to_world(R, resp)), static_cast<Q>(dot(h, resp))};
    }
    const Rot<Q> R = rotation_of<Q>(x.q, true);
    const V3<Q> h = to_body(R, cross(c - x.p, d));
    const V3<Q> resp = had(x.inv_i, h);
    return Arm{to_world(R, resp), dot(h, resp)};
  };
  auto kof = [&](const Arm& aa, const Arm& ab, bool in_T) {
    if (in_T) {
      return static_cast<Q>(((T(a.inv_mass) + T(b.inv_mass)) + T(aa.k)) + T(ab.k));
    }
    return ((a.inv_mass + b.inv_mass) + aa.k) + ab.k;
  };
  auto apply = [&](V3<Q> d, Q s, const Arm& aa, const Arm& ab, bool in_T) {
    if (in_T) {
      const V3<T> p = as<T>(d) * T(s);
      a.v = as<Q>(as<T>(a.v) + p * T(a.inv_mass));
      b.v = as<Q>(as<T>(b.v) - p * T(b.inv_mass));
      a.w = as<Q>(as<T>(a.w) + as<T>(aa.response) * T(s));
      b.w = as<Q>(as<T>(b.w) - as<T>(ab.response) * T(s));
    } else {
      const V3<Q> p = d * s;
      a.v = a.v + p * a.inv_mass;
      b.v = b.v - p * b.inv_mass;
      a.w = a.w + aa.response * s;
      b.w = b.w - ab.response * s;
    }
  };

  const V3<Q> u = velocity(a, b, t_term(kU));
  const Q vn = t_term(kVn) ? static_cast<Q>(dot(as<T>(u), as<T>(n))) : dot(u, n);
  const Arm aa = arm(a, n, t_term(kLever)), ab = arm(b, n, t_term(kLever));
  const Q k = kof(aa, ab, t_term(kK));
  if (!(vn < 0) || !(k > 0)) return {0, 0, 0};
  Q jn;
  V3<Q> j;
  if (t_term(kDiv)) {
    const T jt_ = -((T(1) + T(e)) * T(vn)) / T(k);
    jn = jt_;
    j = as<Q>(as<T>(n) * jt_);
  } else {
    jn = -((1 + e) * vn) / k;
    j = n * jn;
  }
  apply(n, jn, aa, ab, t_term(kApply));
  if (mu > 0) {
    const bool f = t_term(kFric);
    V3<Q> ut;
    if (f) {
      const V3<T> u2 = as<T>(velocity(a, b, true));
      ut = as<Q>(u2 - as<T>(n) * dot(u2, as<T>(n)));
      const T len = qsqrt(dot(as<T>(ut), as<T>(ut)));
      if (!(len > 0)) return j;
      const V3<T> t = as<T>(ut) * (T(1) / len);
      const Arm ta = arm(a, as<Q>(t), true), tb = arm(b, as<Q>(t), true);
      const T kt = T(kof(ta, tb, true));
      const T jt = std::min(len / kt, T(mu) * T(jn));
      return as<Q>(as<T>(j) - t * jt);
    }
    const V3<Q> u2 = velocity(a, b, false);
    ut = u2 - n * dot(u2, n);
    const Q len = qsqrt(dot(ut, ut));
    if (!(len > 0)) return j;
    const V3<Q> t = ut * (Q(1) / len);
    const Arm ta = arm(a, t, false), tb = arm(b, t, false);
    const Q kt = kof(ta, tb, false);
    const Q jt = std::min(len / kt, Q(mu) * jn);
    j = j - t * jt;
  }
  return j;
}

template <class T>
Body body_of(const BodyView<const T>& v, std::size_t i) {
  Body b;
  b.inv_mass = v.inv_mass[i];
  const bool fixed = b.inv_mass == 0;
  b.inv_i = fixed ? V3<Q>{0, 0, 0} : V3<Q>{Q(v.inv_inertia.x[i]), Q(v.inv_inertia.y[i]), Q(v.inv_inertia.z[i])};
  b.p = {Q(v.p.x[i]), Q(v.p.y[i]), Q(v.p.z[i])};
  b.v = {Q(v.v.x[i]), Q(v.v.y[i]), Q(v.v.z[i])};
  b.w = {Q(v.w.x[i]), Q(v.w.y[i]), Q(v.w.z[i])};
  b.q[0] = v.q.w[i];
  b.q[1] = v.q.x[i];
  b.q[2] = v.q.y[i];
  b.q[3] = v.q.z[i];
  return b;
}

template <class T>
void attribute(const char* family, const Scene<T>& s) {
  // The reference and its impulse scale, in __float128.
  Scene<Q> qs = convert_scene<Q>(s);
  ImpulseBuffer<Q> ref(s.contacts.size());
  std::vector<ReferenceContact<Q>> diag(s.contacts.size());
  reference_solve<Q>(qs.bodies.view(), qs.contacts.view(), ref.view(), diag.data());
  // The real kernel, rigid, fast.
  BodyBuffer<T> kb = s.bodies;
  ImpulseBuffer<T> kj(s.contacts.size());
  Schedule schedule;
  schedule.build(s.contacts.view(), kb.view());
  SolverOptions o;
  o.threads = 1;
  Solver(o).solve(Model::rigid, kb.view(), s.contacts.view(), kj.view(), schedule);

  const BodyView<const T> bv = s.bodies.view();
  const ContactView<T> cv = s.contacts.view();
  double worst[kTerms + 2] = {};
  for (std::size_t k = 0; k < cv.count; ++k) {
    const Body a = body_of(bv, cv.a[k]), b = body_of(bv, cv.b[k]);
    const V3<Q> c{Q(cv.c.x[k]), Q(cv.c.y[k]), Q(cv.c.z[k])}, n{Q(cv.n.x[k]), Q(cv.n.y[k]), Q(cv.n.z[k])};
    const Q e = cv.e ? Q(cv.e[k]) : Q(cv.uniform_e), mu = cv.mu ? Q(cv.mu[k]) : Q(0);
    const V3<Q> jr{ref.view().j.x[k], ref.view().j.y[k], ref.view().j.z[k]};
    auto err = [&](V3<Q> j) {
      const V3<Q> d = j - jr;
      return static_cast<double>(normalised_impulse_error<T>(qsqrt(dot(d, d)), diag[k]));
    };
    for (int term = 0; term < kTerms; ++term) worst[term] = std::max(worst[term], err(law<T>(a, b, c, n, e, mu, term)));
    worst[kTerms] = std::max(worst[kTerms], err(law<T>(a, b, c, n, e, mu, -1)));
    const V3<Q> jk{Q(kj.view().j.x[k]), Q(kj.view().j.y[k]), Q(kj.view().j.z[k])};
    worst[kTerms + 1] = std::max(worst[kTerms + 1], err(jk));
  }
  std::printf("%-20s %-6s", family, std::is_same_v<T, float> ? "float" : "double");
  for (const double w : worst) std::printf(" %7.2f", w);
  std::printf("\n");
}

template <class T>
void all_families(std::size_t count) {
  const Fit fit = Fit::rigid;
  attribute<T>("mass-ratio", mass_ratio_family<T>(count, fit, 11).scene());
  attribute<T>("immovable", immovable_family<T>(count, fit, 12).scene());
  attribute<T>("needle", needle_family<T>(count, 13).scene());
  attribute<T>("long-lever", long_lever_family<T>(count, fit, 14).scene());
  attribute<T>("grazing", grazing_family<T>(count, fit, 15).scene());
  attribute<T>("unit-scales", unit_scale_family<T>(count, fit, 16).scene());
  attribute<T>("e-0-and-1", restitution_family<T>(count, fit, 19).scene());
  attribute<T>("stick-slip", stick_slip_family<T>(count, fit, 20).scene());
  attribute<T>("spin-dominated", spin_family<T>(count, fit, 21).scene());
}

}  // namespace
}  // namespace collide::hard

int main(int argc, char** argv) {
  const std::size_t count = argc > 1 ? std::strtoul(argv[1], nullptr, 10) : 1000;
  std::printf("max error per family when only one term runs in T (rigid scenes, %zu contacts), eps * impulse_scale\n",
              count);
  std::printf("%-20s %-6s", "family", "prec");
  for (const char* t : collide::hard::kTermNames) std::printf(" %7s", t);
  std::printf(" %7s %7s\n", "all", "kernel");
  collide::hard::all_families<float>(count);
  collide::hard::all_families<double>(count);
  return 0;
}
