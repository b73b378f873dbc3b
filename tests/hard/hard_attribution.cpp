// hard_attribution.cpp - where the fast mode's impulse error comes from, per
// hard family and per term of the law.
//
// Usage: hard_attribution [count]   (built with the tests, run by hand)
//
// Method. For one contact the law is a chain of terms, each evaluated by the
// fast kernel in a fixed order (contact_kernel.hpp), in its own precision T
// or, where the kernel widens, in its wider arithmetic:
//   n      the stored normal as it is (the law normalises it); the kernel
//          folds its |n|^2 into K (fast_normal_impulse: in double for float,
//          as 1 + |n|^2 - 1 to eps^2 for double)
//   u      relative velocity (va + wa x ra) - (vb + wb x rb), ra = c - pa, in
//          T; the particle model's va - vb in double (float) or exactly as
//          hi + lo (double)
//   vn     u . n in T; the particle model's in double (float) or compensated
//          (double)
//   lever  h = R^T (r x n) as the kernel forms it (float: in double from q
//          normalised, then rounded; double: R from the stored q), invI o h,
//          h . invI o h
//   K      1/ma + 1/mb + ka + kb (float: summed in double; double: in T, the
//          particle's exactly as hi + lo)
//   div    jn = -((1 + e) vn) / K (float: in double, rounded once; double:
//          in T, the particle's compensated), and J = jn n in T
//   apply  v += n jn / m, w += R (invI o h) jn
//   fric   u' after the normal impulse, ut, |ut|, t, K(t), jt = min(|ut|/K(t), mu jn)
// This tool evaluates that chain in __float128 with the inputs exactly as
// stored, except for ONE term which it evaluates as the kernel does (inputs
// rounded to T, the kernel's operations in the kernel's order, result
// widened): the error of J that follows is what that term alone injects.
// The contacts of a scene run in input order on one body state carried in
// __float128, so that on a chain of shared bodies (a cradle, debris) a
// term's error travels down the chain as the kernel's does. "all" runs every
// term as the kernel does and "kernel" is the real kernel (Solver, fast mode,
// the scene's model) for comparison: they agree to the digits shown, which
// checks that the tool replicates the kernel. Errors are in the law's unit,
// eps(T) times the impulse scale of reference_solve<__float128>
// (impulse_error_unit in collide/eval/error_bound.hpp), max over the scene.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <type_traits>
#include <vector>

#include "collide/eval/error_bound.hpp"
#include "collide/eval/hard_scenes.hpp"
#include "collide/eval/reference.hpp"
#include "collide/io/generate.hpp"
#include "collide/schedule.hpp"
#include "collide/solve.hpp"
#include "contact_kernel.hpp"
#include "exact_lanes.hpp"

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

// The fast kernel's compensated pieces (contact_kernel.hpp), on one lane:
// the tool replicates the kernel's arithmetic with the kernel's own helpers.
using Lane = detail::ScalarLanes<double>;
double lane_value(const Lane& x) { return x[0]; }

/// |n|^2 of the stored normal as the fast kernel forms it: float in double,
/// double as 1 + norm_excess (to eps^2), returned as (1, excess) so that
/// nothing is lost in Q.
template <class T>
void kernel_norm2(V3<Q> n, Q& one_plus, double& excess) {
  const V3<T> nt = as<T>(n);
  if constexpr (std::is_same_v<T, float>) {
    const V3<double> nd = as<double>(nt);
    const double nn = dot(nd, nd);
    one_plus = nn;
    excess = nn - 1;
  } else {
    excess = lane_value(detail::norm_excess(detail::Vec3<Lane>{Lane(nt.x), Lane(nt.y), Lane(nt.z)}));
    one_plus = Q(1) + Q(excess);
  }
}

/// The law on one contact of a scene run by `model` (rigid or particle) with
/// the terms in the mask `in_t` evaluated as the fast kernel does (in T, or
/// where the kernel widens, in its wider arithmetic) and the rest in Q.
/// Updates a and b; returns J in Q.
template <class T>
V3<Q> law(Model model, Body& a, Body& b, V3<Q> c, V3<Q> n_stored, Q e, Q mu, unsigned in_t) {
  auto t_term = [&](int term) { return ((in_t >> term) & 1u) != 0; };
  const bool particle = model == Model::particle;
  constexpr bool kFloat = std::is_same_v<T, float>;
  // n: the law normalises; the fast kernel uses the stored n and folds its
  // |n|^2 into K (fast_normal_impulse).
  Q nn = 1;
  double excess = 0;
  V3<Q> n = n_stored * (Q(1) / qsqrt(dot(n_stored, n_stored)));
  if (t_term(kN)) {
    n = n_stored;
    kernel_norm2<T>(n_stored, nn, excess);
  }
  auto velocity = [&](const Body& a_, const Body& b_, bool in_T) {
    if (in_T && particle) {
      // The particle kernel: va - vb in double (float), exactly as hi + lo (double).
      if constexpr (kFloat) return as<Q>(as<double>(as<T>(a_.v)) - as<double>(as<T>(b_.v)));
      return as<Q>(as<T>(a_.v)) - as<Q>(as<T>(b_.v));
    }
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
    if (x.inv_mass == 0 || particle) return Arm{{0, 0, 0}, 0};
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
  // K(d) with the kernel's order; `scale` is the |n|^2 of the normal step.
  auto kof = [&](const Arm& aa, const Arm& ab, bool in_T, Q scale) -> Q {
    if (!in_T) return ((a.inv_mass + b.inv_mass) * scale + aa.k) + ab.k;
    if constexpr (kFloat) {
      // float: the sum in double from the float terms.
      const double kp = double(T(a.inv_mass)) + double(T(b.inv_mass));
      return (kp * double(scale) + double(T(aa.k))) + double(T(ab.k));
    } else {
      if (particle) {
        const Lane kp = Lane(T(a.inv_mass)), kq = Lane(T(b.inv_mass));
        Lane kh, kl;
        detail::two_sum(kp, kq, kh, kl);
        Lane dh, dl;
        detail::fast_two_sum(kh, kl + kh * Lane(double(scale - 1)), dh, dl);
        return Q(lane_value(dh)) + Q(lane_value(dl));
      }
      const T k = ((T(a.inv_mass) + T(b.inv_mass)) + T(aa.k)) + T(ab.k);
      return Q(k + (T(a.inv_mass) + T(b.inv_mass)) * T(scale - 1));
    }
  };
  // K(t) of the friction step, in T as the kernel forms it.
  auto kof_t = [&](const Arm& aa, const Arm& ab) {
    return static_cast<Q>(((T(a.inv_mass) + T(b.inv_mass)) + T(aa.k)) + T(ab.k));
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
  Q vn = dot(u, n);
  if (t_term(kVn)) {
    if (!particle) {
      vn = static_cast<Q>(dot(as<T>(u), as<T>(n)));
    } else if constexpr (kFloat) {
      vn = dot(as<double>(u), as<double>(as<T>(n)));
    } else {
      // The kernel forms u . n compensated from va and vb themselves.
      const V3<T> va = as<T>(a.v), vb = as<T>(b.v), nt = as<T>(n);
      Lane hi, lo;
      detail::compensated_particle_vn(detail::Vec3<Lane>{Lane(va.x), Lane(va.y), Lane(va.z)},
                                      detail::Vec3<Lane>{Lane(vb.x), Lane(vb.y), Lane(vb.z)},
                                      detail::Vec3<Lane>{Lane(nt.x), Lane(nt.y), Lane(nt.z)}, hi, lo);
      vn = Q(lane_value(hi)) + Q(lane_value(lo));
    }
  }
  const Arm aa = arm(a, n, t_term(kLever)), ab = arm(b, n, t_term(kLever));
  const Q k = kof(aa, ab, t_term(kK), nn);
  if (!(vn < 0) || !(k > 0)) return {0, 0, 0};
  Q jn;
  V3<Q> j;
  if (t_term(kDiv)) {
    T jn_t;
    if constexpr (kFloat) {
      jn_t = static_cast<T>(-((1.0 + double(T(e))) * double(vn)) / double(k));
    } else if (particle) {
      const double vh = double(vn), kh = double(k);
      const Lane q = detail::compensated_normal_impulse(Lane(vh), Lane(double(vn - Q(vh))), Lane(T(e)), Lane(kh),
                                                        Lane(double(k - Q(kh))));
      jn_t = lane_value(q);
    } else {
      jn_t = -((T(1) + T(e)) * T(vn)) / T(k);
    }
    jn = jn_t;
    j = as<Q>(as<T>(n) * jn_t);
  } else {
    jn = -((1 + e) * vn) / k;
    j = n * jn;
  }
  apply(n, jn, aa, ab, t_term(kApply));
  if (mu > 0) {
    const bool f = t_term(kFric);
    V3<Q> ut;
    if (f) {
      const V3<T> u2 = as<T>(velocity(a, b, !particle));
      ut = as<Q>(u2 - as<T>(n) * dot(u2, as<T>(n)));
      const T len = qsqrt(dot(as<T>(ut), as<T>(ut)));
      if (!(len > 0)) return j;
      const V3<T> t = as<T>(ut) * (T(1) / len);
      const Arm ta = arm(a, as<Q>(t), true), tb = arm(b, as<Q>(t), true);
      const T kt = T(kof_t(ta, tb));
      const T jt = std::min(len / kt, T(mu) * T(jn));
      apply(as<Q>(t), -Q(jt), ta, tb, true);
      return as<Q>(as<T>(j) - t * jt);
    }
    const V3<Q> u2 = velocity(a, b, false);
    ut = u2 - n * dot(u2, n);
    const Q len = qsqrt(dot(ut, ut));
    if (!(len > 0)) return j;
    const V3<Q> t = ut * (Q(1) / len);
    const Arm ta = arm(a, t, false), tb = arm(b, t, false);
    const Q kt = ((a.inv_mass + b.inv_mass) + ta.k) + tb.k;
    const Q jt = std::min(len / kt, Q(mu) * jn);
    apply(t, -jt, ta, tb, t_term(kApply));
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
void attribute(const char* family, const Scene<T>& s, Model model = Model::rigid) {
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
  Solver(o).solve(model, kb.view(), s.contacts.view(), kj.view(), schedule);

  // Each variant runs the contacts in input order on one body state carried
  // in Q (bodies move as the law moves them), so that a term's error on a
  // chain of shared bodies (a cradle, debris) is followed down the chain as
  // the kernel's is; on a pairs scene every contact starts from the stored
  // bodies, as before.
  const BodyView<const T> bv = s.bodies.view();
  const ContactView<T> cv = s.contacts.view();
  std::vector<Body> start(bv.count);
  for (std::size_t i = 0; i < bv.count; ++i) start[i] = body_of(bv, i);
  constexpr unsigned kAll = (1u << kTerms) - 1;
  const unsigned masks[] = {1u << kN,   1u << kU,     1u << kVn,   1u << kLever, 1u << kK,
                            1u << kDiv, 1u << kApply, 1u << kFric, kAll};
  constexpr int kColumns = sizeof(masks) / sizeof(masks[0]);
  double worst[kColumns + 1] = {};
  for (int col = 0; col < kColumns; ++col) {
    std::vector<Body> state = start;
    double& w = worst[col];
    for (std::size_t k = 0; k < cv.count; ++k) {
      const V3<Q> c{Q(cv.c.x[k]), Q(cv.c.y[k]), Q(cv.c.z[k])}, n{Q(cv.n.x[k]), Q(cv.n.y[k]), Q(cv.n.z[k])};
      const Q e = cv.e ? Q(cv.e[k]) : Q(cv.uniform_e), mu = cv.mu ? Q(cv.mu[k]) : Q(0);
      const V3<Q> jr{ref.view().j.x[k], ref.view().j.y[k], ref.view().j.z[k]};
      const V3<Q> d = law<T>(model, state[cv.a[k]], state[cv.b[k]], c, n, e, mu, masks[col]) - jr;
      w = std::max(w, static_cast<double>(normalised_impulse_error<T>(qsqrt(dot(d, d)), diag[k])));
    }
  }
  for (std::size_t k = 0; k < cv.count; ++k) {
    const V3<Q> jr{ref.view().j.x[k], ref.view().j.y[k], ref.view().j.z[k]};
    const V3<Q> d = V3<Q>{Q(kj.view().j.x[k]), Q(kj.view().j.y[k]), Q(kj.view().j.z[k])} - jr;
    worst[kColumns] =
        std::max(worst[kColumns], static_cast<double>(normalised_impulse_error<T>(qsqrt(dot(d, d)), diag[k])));
  }
  std::printf("%-20s %-6s", family, std::is_same_v<T, float> ? "float" : "double");
  for (const double w : worst) std::printf(" %7.2f", w);
  std::printf("\n");
}

template <class T>
void all_families(std::size_t count) {
  const Model fit = Model::rigid;
  attribute<T>("mass-ratio", mass_ratio_family<T>(count, fit, 11).scene());
  attribute<T>("immovable", immovable_family<T>(count, fit, 12).scene());
  attribute<T>("needle", needle_family<T>(count, 13).scene());
  attribute<T>("long-lever", long_lever_family<T>(count, fit, 14).scene());
  attribute<T>("grazing", grazing_family<T>(count, fit, 15).scene());
  attribute<T>("unit-scales", unit_scale_family<T>(count, fit, 16).scene());
  attribute<T>("e-0-and-1", restitution_family<T>(count, fit, 19).scene());
  attribute<T>("stick-slip", stick_slip_family<T>(count, fit, 20).scene());
  attribute<T>("spin-dominated", spin_family<T>(count, fit, 21).scene());
  // Chains of shared bodies, rigid kernel: the cradles along a random axis
  // (test_hard_shared's: sphere-shaped, run by the rigid kernel here).
  for (const char* family : {"cradle", "cradle-mixed"}) {
    attribute<T>(family, build_hard_scene<T>({family, Model::sphere, true, false}, count));
  }
  // The report's scenes (generate.hpp) shaped for the particle model, run
  // by the particle kernel, 100 times `count` contacts.
  GenerateOptions particle;
  particle.model = Model::particle;
  attribute<T>("pairs-particle", generate_pairs<T>(count * 100, particle), Model::particle);
  attribute<T>("debris-particle", generate_debris<T>(count * 100, particle), Model::particle);
  // The same scenes as drawn (rigid bodies, moments in [0.1, 20) each), run
  // by the rigid kernel.
  attribute<T>("pairs-rigid", generate_pairs<T>(count * 100, GenerateOptions{}), Model::rigid);
  attribute<T>("debris-rigid", generate_debris<T>(count * 100, GenerateOptions{}), Model::rigid);
}

}  // namespace
}  // namespace collide::hard

int main(int argc, char** argv) {
  const std::size_t count = argc > 1 ? std::strtoul(argv[1], nullptr, 10) : 1000;
  std::printf(
      "max error per family when only one term runs as the fast kernel does (rigid kernel, %zu contacts; "
      "pairs-* and debris-*: %zu contacts), eps * impulse_scale\n",
      count, count * 100);
  std::printf("%-20s %-6s", "family", "prec");
  for (const char* t : collide::hard::kTermNames) std::printf(" %7s", t);
  std::printf(" %7s %7s\n", "all", "kernel");
  collide::hard::all_families<float>(count);
  collide::hard::all_families<double>(count);
  return 0;
}
