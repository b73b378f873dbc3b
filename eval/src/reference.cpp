// reference.cpp - the law of docs/collision-law.md, transcribed.
//
// World frame, 3x3 matrices, Iw^-1 = R diag(1/I) R^T (applied as its three
// factors, see RefBody), contacts in input order. No lanes and no local-frame
// shortcut: this is the independent statement that the local-frame kernel is
// checked against. It reads the same stored inputs as the kernels (inverse
// mass, inverse moments, q, n), so that a difference measures the kernel's
// arithmetic, not input rounding. q and n are normalised here in S, as the
// law says: a double normal widened to long double is unit only to double
// precision, and K(n) = 1/ma + 1/mb + ... assumes |n| = 1 (without this the
// reference was only double-accurate).
//
// Written over a plain 3-vector of S rather than Eigen, so that one
// transcription serves double, long double (64-bit mantissa) and, where GCC
// has it, __float128 (113 bits, libquadmath's sqrtq): long double is too
// short to judge the accurate mode in double (a grazing contact amplifies its
// 5e-20 rounding by 1e7, far above double's ulp), and Eigen has no numeric
// traits for __float128. Every operation is a correctly rounded +, -, *, /
// or sqrt in S.
//
// One transcription: textbook_solve, the report's and the benchmarks'
// baseline, is this code without the error analysis, in the scene's own
// precision.
#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>
#include <utility>
#include <vector>

#include "collide/eval/reference.hpp"

#include "collide/accuracy.hpp"
#include "collide/eval/check.hpp"
#include "collide/io/scene.hpp"

#if COLLIDE_HAS_FLOAT128
#include <quadmath.h>
#endif

namespace collide {
namespace {

template <class S>
S ref_sqrt(S x) {
  return std::sqrt(x);
}
#if COLLIDE_HAS_FLOAT128
template <>
__float128 ref_sqrt(__float128 x) {
  return sqrtq(x);
}
#endif

template <class S>
S ref_abs(S x) {
  return x < S(0) ? -x : x;
}

/// A 3-vector of S with the few operations the law needs (Eigen's names).
template <class S>
struct Vec {
  S v[3] = {S(0), S(0), S(0)};
  Vec() = default;
  Vec(S x, S y, S z) : v{x, y, z} {}
  S x() const { return v[0]; }
  S y() const { return v[1]; }
  S z() const { return v[2]; }
  static Vec Zero() { return {}; }
  Vec operator+(const Vec& b) const { return {v[0] + b.v[0], v[1] + b.v[1], v[2] + b.v[2]}; }
  Vec operator-(const Vec& b) const { return {v[0] - b.v[0], v[1] - b.v[1], v[2] - b.v[2]}; }
  Vec operator*(S s) const { return {v[0] * s, v[1] * s, v[2] * s}; }
  Vec operator/(S s) const { return {v[0] / s, v[1] / s, v[2] / s}; }
  Vec& operator+=(const Vec& b) { return *this = *this + b; }
  Vec& operator-=(const Vec& b) { return *this = *this - b; }
  friend Vec operator*(S s, const Vec& a) { return a * s; }
  S dot(const Vec& b) const { return v[0] * b.v[0] + v[1] * b.v[1] + v[2] * b.v[2]; }
  Vec cross(const Vec& b) const {
    return {v[1] * b.v[2] - v[2] * b.v[1], v[2] * b.v[0] - v[0] * b.v[2], v[0] * b.v[1] - v[1] * b.v[0]};
  }
  Vec cwiseProduct(const Vec& b) const { return {v[0] * b.v[0], v[1] * b.v[1], v[2] * b.v[2]}; }
  Vec cwiseAbs() const { return {ref_abs(v[0]), ref_abs(v[1]), ref_abs(v[2])}; }
  S squaredNorm() const { return dot(*this); }
  S norm() const { return ref_sqrt(squaredNorm()); }
  Vec normalized() const { return *this / norm(); }
  S maxCoeff() const { return std::max({v[0], v[1], v[2]}); }
};

/// A rotation matrix of S, row-major.
template <class S>
struct Rot {
  S m[3][3];
  Vec<S> operator*(const Vec<S>& x) const {
    return {m[0][0] * x.v[0] + m[0][1] * x.v[1] + m[0][2] * x.v[2],
            m[1][0] * x.v[0] + m[1][1] * x.v[1] + m[1][2] * x.v[2],
            m[2][0] * x.v[0] + m[2][1] * x.v[1] + m[2][2] * x.v[2]};
  }
  /// R^T x.
  Vec<S> transposed_times(const Vec<S>& x) const {
    return {m[0][0] * x.v[0] + m[1][0] * x.v[1] + m[2][0] * x.v[2],
            m[0][1] * x.v[0] + m[1][1] * x.v[1] + m[2][1] * x.v[2],
            m[0][2] * x.v[0] + m[1][2] * x.v[1] + m[2][2] * x.v[2]};
  }
  /// The rotation of the unit quaternion (w, x, y, z), as Eigen forms it.
  static Rot of_unit_quaternion(S w, S x, S y, S z) {
    const S tx = 2 * x, ty = 2 * y, tz = 2 * z;
    const S twx = tx * w, twy = ty * w, twz = tz * w;
    const S txx = tx * x, txy = ty * x, txz = tz * x;
    const S tyy = ty * y, tyz = tz * y, tzz = tz * z;
    Rot r;
    r.m[0][0] = S(1) - (tyy + tzz);
    r.m[0][1] = txy - twz;
    r.m[0][2] = txz + twy;
    r.m[1][0] = txy + twz;
    r.m[1][1] = S(1) - (txx + tzz);
    r.m[1][2] = tyz - twx;
    r.m[2][0] = txz - twy;
    r.m[2][1] = tyz + twx;
    r.m[2][2] = S(1) - (txx + tyy);
    return r;
  }
};

template <class S>
struct RefBody {
  using V3 = Vec<S>;
  using M3 = Rot<S>;

  S inv_mass;
  S inv_inertia_max;  // the largest eigenvalue of Iw^-1 (0 for an immovable body)
  M3 rotation;        // R, body to world
  V3 inv_inertia;     // diag(1/Ix, 1/Iy, 1/Iz), body frame
  V3 p, v, w;

  /// Iw^-1 x = R diag(1/I) R^T x, applied factor by factor. Forming the
  /// matrix R diag(1/I) R^T first loses the small eigenvalues to the
  /// rounding of the large one: with a moment ratio of 1e-12 (a needle) the
  /// formed matrix was off by ~1e-7 relative even in long double, and the
  /// reference, not the kernel, was wrong.
  V3 inv_inertia_world(const V3& x) const { return rotation * inv_inertia.cwiseProduct(rotation.transposed_times(x)); }

  RefBody(const BodyView<S>& bodies, std::size_t i) {
    inv_mass = bodies.inv_mass[i];
    // The law: a body with m = inf is immovable whatever its I.
    const bool immovable = inv_mass == S(0);
    const V3 inv_i =
        immovable ? V3::Zero() : V3(bodies.inv_inertia.x[i], bodies.inv_inertia.y[i], bodies.inv_inertia.z[i]);
    const S qw = bodies.q.w[i], qx = bodies.q.x[i], qy = bodies.q.y[i], qz = bodies.q.z[i];
    const S qn = ref_sqrt(qw * qw + qx * qx + qy * qy + qz * qz);
    rotation = M3::of_unit_quaternion(qw / qn, qx / qn, qy / qn, qz / qn);
    inv_inertia = inv_i;
    inv_inertia_max = inv_i.maxCoeff();
    p = V3(bodies.p.x[i], bodies.p.y[i], bodies.p.z[i]);
    v = V3(bodies.v.x[i], bodies.v.y[i], bodies.v.z[i]);
    w = V3(bodies.w.x[i], bodies.w.y[i], bodies.w.z[i]);
  }

  void store(const BodyView<S>& bodies, std::size_t i) const {
    if (inv_mass == S(0)) return;  // immovable bodies are never written
    bodies.v.x[i] = v.x();
    bodies.v.y[i] = v.y();
    bodies.v.z[i] = v.z();
    bodies.w.x[i] = w.x();
    bodies.w.y[i] = w.y();
    bodies.w.z[i] = w.z();
  }
};

/// The law for every contact in input order. With kErrorAnalysis, also the
/// scales the kernels' errors are measured against (ReferenceContact); without
/// it, the law alone: the same operations on the same values, so the two give
/// the same J and velocities.
template <class S, bool kErrorAnalysis>
void solve_law(const BodyView<S>& bodies, const ContactView<S>& contacts, const ImpulseView<S>& impulses,
               ReferenceContact<S>* diagnostics, const SolveSequence& sequence) {
  using V3 = Vec<S>;
  // The uncertainty each body's velocities inherit from the contacts applied
  // to it before in the pass (linear [m/s] and angular [rad/s], in units of
  // C eps): a kernel's impulse on a contact is off by up to C eps s (s the
  // scale of its own rounding), which moves the body by up to C eps s / m
  // and, angularly, C eps s max(1/I) |r|; a later contact on that body sees
  // its relative velocity off by that much on top of its own rounding. This
  // keeps the bound C eps s a statement about every contact of a chain, not
  // only about the first one: without it, contacts deep in the debris
  // scene's chains exceeded the bound (docs/decisions/0008-the-impulse-scale.md).
  std::vector<S> inherited_v(kErrorAnalysis ? bodies.count : 0, S(0));
  std::vector<S> inherited_w(kErrorAnalysis ? bodies.count : 0, S(0));
  // The accumulated passes' totals (Iteration::accumulate): the normal
  // impulse lambda n, the target u . n, and the friction impulse -G taken
  // from a. The first pass is the law and records them.
  const bool accumulates = sequence.iteration == Iteration::accumulate;
  std::vector<S> total_normal(accumulates ? contacts.count : 0, S(0));
  std::vector<S> target(accumulates ? contacts.count : 0, S(0));
  std::vector<Vec<S>> total_friction(accumulates ? contacts.count : 0, Vec<S>::Zero());
  // A warm start's totals come from the J the arrays hold (SolverOptions::
  // warm_start): lambda the part along the unit normal, never below 0, and
  // the rest as -G where friction can act (mu > 0). Visits of their own
  // measure the targets and apply the totals; every pass is then a later one.
  const bool warm = accumulates && sequence.warm_start;
  std::vector<S> warm_size(warm ? contacts.count : 0, S(0));
  if (warm) {
    for (std::size_t k = 0; k < contacts.count; ++k) {
      const V3 jw(impulses.j.x[k], impulses.j.y[k], impulses.j.z[k]);
      const V3 n = V3(contacts.n.x[k], contacts.n.y[k], contacts.n.z[k]).normalized();
      const S lambda = std::max(jw.dot(n), S(0));
      total_normal[k] = lambda;
      const S mu = contacts.mu ? contacts.mu[k] : S(0);
      if (mu > S(0)) total_friction[k] = lambda * n - jw;
      warm_size[k] = jw.norm();
    }
  }
  if (warm) {
    // The warm start's two visits, before the passes (as the kernels' own
    // walks): every target from the velocities the solve was given (a
    // contact that does not approach then, or has no movable body, asks for
    // none), then each contact's totals applied in the sequence. What the
    // kernel rounds in applying them reaches the bodies' contacts as any
    // impulse's does.
    const auto visit = [&](std::size_t at, bool apply_totals) {
      const std::size_t k = sequence.order != nullptr ? sequence.order[at] : at;
      const std::size_t ia = contacts.a[k];
      const std::size_t ib = contacts.b[k];
      RefBody<S> a(bodies, ia);
      RefBody<S> b(bodies, ib);
      const V3 c(contacts.c.x[k], contacts.c.y[k], contacts.c.z[k]);
      const V3 n = V3(contacts.n.x[k], contacts.n.y[k], contacts.n.z[k]).normalized();
      const V3 ra = c - a.p;
      const V3 rb = c - b.p;
      const V3 ran = ra.cross(n);
      const V3 rbn = rb.cross(n);
      const S k_n = a.inv_mass + b.inv_mass + ran.dot(a.inv_inertia_world(ran)) + rbn.dot(b.inv_inertia_world(rbn));
      if (!apply_totals) {
        const S e = contacts.e ? contacts.e[k] : contacts.uniform_e;
        const S vn = V3((a.v + a.w.cross(ra)) - (b.v + b.w.cross(rb))).dot(n);
        target[k] = k_n != S(0) && vn < S(0) ? -e * vn : S(0);
        return;
      }
      if (k_n == S(0)) {
        total_normal[k] = S(0);
        total_friction[k] = V3::Zero();
        return;
      }
      const V3 p = total_normal[k] * n - total_friction[k];
      a.v += p * a.inv_mass;
      a.w += a.inv_inertia_world(ra.cross(p));
      b.v -= p * b.inv_mass;
      b.w -= b.inv_inertia_world(rb.cross(p));
      a.store(bodies, ia);
      b.store(bodies, ib);
      if constexpr (kErrorAnalysis) {
        const S size = warm_size[k];
        inherited_v[ia] += size * a.inv_mass;
        inherited_w[ia] += size * a.inv_inertia_max * ra.norm();
        inherited_v[ib] += size * b.inv_mass;
        inherited_w[ib] += size * b.inv_inertia_max * rb.norm();
      }
    };
    for (std::size_t at = 0; at < contacts.count; ++at) visit(at, false);
    for (std::size_t at = 0; at < contacts.count; ++at) visit(at, true);
  }
  for (std::size_t step = 0; step < sequence.passes * contacts.count; ++step) {
    const std::size_t pass = step / contacts.count;
    const std::size_t at = step % contacts.count;
    const std::size_t k = sequence.order != nullptr ? sequence.order[at] : at;
    // Each pass is measured as a one-pass solve from the velocities the pass
    // before left: the uncertainty carried along chains restarts with it.
    // Carried over, it compounded: every pass multiplied it by what a body's
    // contacts add to it (each contact counts the uncertainty of both bodies
    // into its scale and then hands its scale back to both), so a pile's
    // scales grew by orders of magnitude a pass and no impulse could fail the
    // bound. What an earlier pass got wrong is not lost by the restart: it is
    // drift in the velocities, which the later passes undo as they undo any
    // approach, and the sum's scale still counts that pass's own scale
    // (docs/collision-law.md, "The error bound over passes").
    if (kErrorAnalysis && at == 0 && pass > 0) {
      std::fill(inherited_v.begin(), inherited_v.end(), S(0));
      std::fill(inherited_w.begin(), inherited_w.end(), S(0));
    }
    const std::size_t ia = contacts.a[k];
    const std::size_t ib = contacts.b[k];
    RefBody<S> a(bodies, ia);
    RefBody<S> b(bodies, ib);
    const V3 c(contacts.c.x[k], contacts.c.y[k], contacts.c.z[k]);
    const V3 n = V3(contacts.n.x[k], contacts.n.y[k], contacts.n.z[k]).normalized();
    const S e = contacts.e ? contacts.e[k] : contacts.uniform_e;
    const S mu = contacts.mu ? contacts.mu[k] : S(0);

    const V3 ra = c - a.p;
    const V3 rb = c - b.p;
    auto relative_velocity = [&] { return V3((a.v + a.w.cross(ra)) - (b.v + b.w.cross(rb))); };
    // The speeds' own part (what this evaluation rounds) and, on top, the
    // uncertainty the bodies inherited.
    auto own_speed_scale = [&] { return a.v.norm() + a.w.norm() * ra.norm() + b.v.norm() + b.w.norm() * rb.norm(); };
    auto inherited_speed = [&] {
      return inherited_v[ia] + inherited_w[ia] * ra.norm() + inherited_v[ib] + inherited_w[ib] * rb.norm();
    };
    auto inv_effective_mass = [&](const V3& d) {
      const V3 rad = ra.cross(d);
      const V3 rbd = rb.cross(d);
      return a.inv_mass + b.inv_mass + rad.dot(a.inv_inertia_world(rad)) + rbd.dot(b.inv_inertia_world(rbd));
    };
    // How much K(d) moves with the rounding of the lever arms: each body's
    // term is h . (invI * h) with h = R^T (r x d), and h is computed with
    // cancellation, to an absolute error of about eps |r| per component, so
    // K(d) is off by up to eps * 2 sum_bodies |r| sum_i invI_i |h_i|. For a
    // needle (one inverse moment 1e12 times the others) or a normal nearly
    // along r (|h| << |r|) that is many times eps K(d).
    auto lever_sensitivity = [&](const V3& d) {
      auto body = [&](const RefBody<S>& x, const V3& r) {
        const V3 h = x.rotation.transposed_times(r.cross(d));
        return r.norm() * x.inv_inertia.dot(h.cwiseAbs());
      };
      return S(2) * (body(a, ra) + body(b, rb));
    };
    // W d, the compliance of the contact: K(d) = d . W d.
    auto compliance_times = [&](const V3& d) {
      return V3((a.inv_mass + b.inv_mass) * d + a.inv_inertia_world(ra.cross(d)).cross(ra) +
                b.inv_inertia_world(rb.cross(d)).cross(rb));
    };
    auto apply = [&](const V3& p) {
      a.v += p * a.inv_mass;
      a.w += a.inv_inertia_world(ra.cross(p));
      b.v -= p * b.inv_mass;
      b.w -= b.inv_inertia_world(rb.cross(p));
    };

    ReferenceContact<S> d;
    const V3 u = relative_velocity();
    d.vn = u.dot(n);
    d.k_n = inv_effective_mass(n);
    V3 j = V3::Zero();
    // The scale is defined for every contact with a movable body, approaching
    // or not: a kernel that rounds a near-zero vn to the other side owes an
    // error measured against it.
    // own_scale: the same scale from the speeds alone, what this
    // evaluation's own rounding can move J by; it is what the bodies inherit.
    S own_scale = 0;
    S own_before = 0;
    // What the kernel rounds in turning a warm start's J into totals is of
    // the size of |J|: it joins the first pass's scale.
    const S warm_scale = warm && pass == 0 ? warm_size[k] : S(0);
    if constexpr (kErrorAnalysis) {
      own_before = own_speed_scale();
      d.speed_scale = own_before + inherited_speed();
      if (d.k_n != S(0)) {
        const S lever = ref_abs(d.vn) * lever_sensitivity(n) / d.k_n;
        d.impulse_scale = (S(1) + e) * (d.speed_scale + lever) / d.k_n + warm_scale;
        own_scale = (S(1) + e) * (own_before + lever) / d.k_n;
      }
    }
    // The friction step's share of the scale (see below), for a normal
    // impulse jn and a friction impulse jt along t.
    [[maybe_unused]] auto friction_scale = [&](S normal_scale, S before, S after, S jn, S jt, const V3& t, S k_t) {
      const S after_normal = normal_scale * compliance_times(n).norm() +
                             jn * (a.inv_inertia_max * ra.squaredNorm() + b.inv_inertia_max * rb.squaredNorm());
      return (S(1) + mu) * normal_scale +
             (before + after + after_normal) / k_t * (S(1) + compliance_times(t).norm() / k_t) +
             jt * lever_sensitivity(t) / k_t;
    };
    if (accumulates && (pass > 0 || warm)) {
      // A later accumulated pass (docs/collision-law.md, "Iteration"): the
      // normal total moved towards the target and clamped at 0, then the
      // friction total moved by what stops the sliding and clamped to the
      // cone of the normal total.
      if (d.k_n != S(0)) {
        const S total = total_normal[k] + (target[k] - d.vn) / d.k_n;
        const S normal = total > S(0) ? total : S(0);
        d.jn = normal;
        apply((normal - total_normal[k]) * n);
        total_normal[k] = normal;
        if (mu > S(0)) {
          const V3 u2 = relative_velocity();
          const V3 ut = u2 - u2.dot(n) * n;
          const S ut_len = ut.norm();
          V3 t = V3::Zero();
          S stop = 0;
          if (ut_len > S(0)) {
            t = ut / ut_len;
            d.k_t = inv_effective_mass(t);
            stop = ut_len / d.k_t;
          }
          const V3 wanted = total_friction[k] + t * stop;
          const S cap = mu * normal;
          const S len = wanted.norm();
          const V3 friction = len > cap ? wanted * (cap / len) : wanted;
          d.jt = friction.norm();
          if constexpr (kErrorAnalysis) {
            if (ut_len > S(0)) {
              const S own_after = own_speed_scale();
              d.impulse_scale =
                  friction_scale(d.impulse_scale, d.speed_scale, own_after + inherited_speed(), d.jn, d.jt, t, d.k_t);
              own_scale = friction_scale(own_scale, own_before, own_after, d.jn, d.jt, t, d.k_t);
            }
          }
          apply(total_friction[k] - friction);
          total_friction[k] = friction;
        }
        a.store(bodies, ia);
        b.store(bodies, ib);
      }
      j = total_normal[k] * n - total_friction[k];
    } else if (d.vn < S(0) && d.k_n != S(0)) {
      d.jn = -(S(1) + e) * d.vn / d.k_n;
      apply(d.jn * n);
      j = d.jn * n;
      if (mu > S(0)) {
        const V3 u2 = relative_velocity();
        const V3 ut = u2 - u2.dot(n) * n;
        const S ut_len = ut.norm();
        if (ut_len > S(0)) {
          const V3 t = ut / ut_len;
          d.k_t = inv_effective_mass(t);
          d.jt = std::min(ut_len / d.k_t, mu * d.jn);
          // The friction step rounds twice over: ut carries the rounding of
          // both velocity evaluations (speed scales before and after the
          // normal impulse), and t = ut/|ut| inherits it as a direction
          // error dt that moves K(t) by 2 t.W dt, i.e. relatively by up to
          // |W t| / K(t) per unit of relative velocity error. That factor is
          // 1 for an isotropic contact and tens for a long lever arm on a
          // body with one small moment, where the plain scale was exceeded.
          // And on the sliding side jt = mu jn carries mu times the error of
          // jn (mu may exceed 1).
          //
          // The friction step also comes after this contact's own normal
          // impulse, and u' inherits two errors of it that S' (the speeds
          // after it) does not count: the error of jn, up to C eps s_n (s_n
          // the normal part of the scale), which moves u' by that times
          // |W n|; and the rounding of the update w += Iw^-1 (r x n) jn,
          // which is relative to max(1/I) |r| jn per body (the rounding of
          // R^T (r x n) meets the largest inverse moment), not to the
          // possibly much smaller change it makes, and reaches u' times |r|:
          //   after_normal = s_n |W n| + jn sum_bodies max(1/I) |r|^2.
          // Without it, a debris contact with a long lever arm on a body of
          // unequal moments exceeded the bound in reference_solve<double>
          // (docs/collision-law.md, "The friction step after the normal
          // impulse"; docs/decisions/0008-the-impulse-scale.md).
          if constexpr (kErrorAnalysis) {
            const S own_after = own_speed_scale();
            d.impulse_scale =
                friction_scale(d.impulse_scale, d.speed_scale, own_after + inherited_speed(), d.jn, d.jt, t, d.k_t);
            own_scale = friction_scale(own_scale, own_before, own_after, d.jn, d.jt, t, d.k_t);
          }
          apply(-d.jt * t);
          j -= d.jt * t;
          if (accumulates) total_friction[k] = d.jt * t;
        }
      }
      if (accumulates) {
        total_normal[k] = d.jn;
        target[k] = -e * d.vn;
      }
      a.store(bodies, ia);
      b.store(bodies, ib);
    }
    // J of the passes so far plus this one's (the accumulated passes' J is
    // their totals).
    if (pass > 0 && !accumulates) j += V3(impulses.j.x[k], impulses.j.y[k], impulses.j.z[k]);
    impulses.j.x[k] = j.x();
    impulses.j.y[k] = j.y();
    impulses.j.z[k] = j.z();
    if constexpr (kErrorAnalysis) {
      // Whether or not the reference applied an impulse: a kernel may have
      // applied one of up to C eps s where vn was within rounding of 0.
      inherited_v[ia] += own_scale * a.inv_mass;
      inherited_w[ia] += own_scale * a.inv_inertia_max * ra.norm();
      inherited_v[ib] += own_scale * b.inv_mass;
      inherited_w[ib] += own_scale * b.inv_inertia_max * rb.norm();
      // Over several passes J is a sum, off by at most the sum of the
      // passes' errors: the scales add up.
      if (diagnostics) {
        if (pass > 0) d.impulse_scale += diagnostics[k].impulse_scale;
        diagnostics[k] = d;
      }
    }
  }
}

/// The precision the replay of a pass sum runs in: the next shorter one that
/// holds the inputs exactly (none for double).
template <class S>
struct ShorterPrecision {
  using type = void;
};
template <>
struct ShorterPrecision<long double> {
  using type = double;
};
#if COLLIDE_HAS_FLOAT128
template <>
struct ShorterPrecision<__float128> {
  using type = long double;
};
#endif

}  // namespace

template <class S>
void reference_solve(const BodyView<S>& bodies, const ContactView<S>& contacts, const ImpulseView<S>& impulses,
                     ReferenceContact<S>* diagnostics, const SolveSequence& sequence) {
  using R = typename ShorterPrecision<S>::type;
  if constexpr (!std::is_void_v<R>) {
    if (diagnostics != nullptr && (sequence.passes > 1 || sequence.warm_start)) {
      // Over several passes the law itself may amplify rounding: Coulomb
      // friction's passes are not a contraction, and two evaluations that
      // differ by rounding can drift apart pass after pass, which no
      // contact's own scale foresees. The same sequence replayed in the
      // shorter precision R shows where: a contact whose replay is off by
      // more than the fast mode's target in R's eps-units has its scale
      // widened by that factor, so the bound measures the kernel's rounding
      // and not the problem's conditioning (docs/collision-law.md, "The
      // error bound over passes").
      BodyBuffer<R> replay_bodies = convert_bodies<R>(bodies);
      const ContactBuffer<R> replay_contacts = convert_contacts<R>(contacts);
      ImpulseBuffer<R> replay_j(contacts.count);
      if (sequence.warm_start) {  // the same warm start, exactly: R holds the kernel's J
        for (std::size_t k = 0; k < contacts.count; ++k) {
          replay_j.view().j.x[k] = R(impulses.j.x[k]);
          replay_j.view().j.y[k] = R(impulses.j.y[k]);
          replay_j.view().j.z[k] = R(impulses.j.z[k]);
        }
      }
      solve_law<R, false>(replay_bodies.view(), replay_contacts.view(), replay_j.view(), nullptr, sequence);
      solve_law<S, true>(bodies, contacts, impulses, diagnostics, sequence);
      const ImpulseView<const R> r = std::as_const(replay_j).view();
      for (std::size_t k = 0; k < contacts.count; ++k) {
        const S dx = impulses.j.x[k] - S(r.j.x[k]);
        const S dy = impulses.j.y[k] - S(r.j.y[k]);
        const S dz = impulses.j.z[k] - S(r.j.z[k]);
        const S unit = S(std::numeric_limits<R>::epsilon()) * diagnostics[k].impulse_scale * S(kImpulseErrorTargetEps);
        if (!(unit > S(0))) continue;
        const S amplified = ref_sqrt(dx * dx + dy * dy + dz * dz) / unit;
        if (amplified > S(1)) diagnostics[k].impulse_scale *= amplified;
      }
      return;
    }
  }
  solve_law<S, true>(bodies, contacts, impulses, diagnostics, sequence);
}

template <class T>
void textbook_solve(const BodyView<T>& bodies, const ContactView<T>& contacts, const ImpulseView<T>& impulses) {
  solve_law<T, false>(bodies, contacts, impulses, nullptr, SolveSequence{});
}
template void textbook_solve<float>(const BodyView<float>&, const ContactView<float>&, const ImpulseView<float>&);
template void textbook_solve<double>(const BodyView<double>&, const ContactView<double>&, const ImpulseView<double>&);

template void reference_solve<double>(const BodyView<double>&, const ContactView<double>&, const ImpulseView<double>&,
                                      ReferenceContact<double>*, const SolveSequence&);
template void reference_solve<long double>(const BodyView<long double>&, const ContactView<long double>&,
                                           const ImpulseView<long double>&, ReferenceContact<long double>*,
                                           const SolveSequence&);
#if COLLIDE_HAS_FLOAT128
template void reference_solve<__float128>(const BodyView<__float128>&, const ContactView<__float128>&,
                                          const ImpulseView<__float128>&, ReferenceContact<__float128>*,
                                          const SolveSequence&);
#endif

}  // namespace collide
