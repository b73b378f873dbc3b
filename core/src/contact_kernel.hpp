// contact_kernel.hpp - the collision law for W contacts at once, written once
// over a lane type and a body model, and instantiated for the scalar path
// (W = 1), the SIMD paths (W = 4 float / 2 double with SSE2, 8 / 4 with AVX2,
// 16 / 8 with AVX-512) and the three body models (particle, sphere, rigid;
// see collide/model.hpp).
//
// Derivation (docs/collision-law.md has the full statement)
// ----------------------------------------------------------
// A contact at world point c joins body a (offset ra = c - pa) and body b
// (rb = c - pb). The velocity of a's material point relative to b's is
//     u = (va + wa x ra) - (vb + wb x rb),   vn = u . n   (< 0: approaching).
// An impulse P on a (and -P on b) changes that velocity along a direction d by
//     du . d = K(d) (P . d),
//     K(d) = 1/ma + 1/mb + (ra x d) . Iwa^-1 (ra x d) + (rb x d) . Iwb^-1 (rb x d),
// the inverse "apparent mass" the contact sees. With Iw^-1 = R diag(1/I) R^T
// the rotational terms are computed in each body's own frame, the source
// page's method: h = R^T (r x d) is the lever arm seen from the body, and
//     (r x d) . Iw^-1 (r x d) = h . (invI * h)          (component-wise product).
// The page's H vector is h scaled by sqrt(invI * m), and its 1 + |H|^2 over m
// is 1/m plus this term. Every term of K is a sum of non-negative products;
// the cancellation is inside h = R^T (r x d), whose components carry an
// absolute error of about eps |r|, which a huge inverse moment (a needle) or
// a normal nearly along r amplifies (docs/collision-law.md, "The lever
// arms"). The normal impulse that gives separation speed -e vn is
//     jn = -(1 + e) vn / K(n),
// and applying P = jn n changes
//     va += P / ma,   wa += R (invI * h_a) jn,   vb -= P / mb,   wb -= R (invI * h_b) jn.
// (R (invI * h) is Iw^-1 (r x n): the angular response per unit impulse, back
// in the world frame; lever_arm returns it.)
//
// Friction, only where mu > 0: with u' the relative velocity after the normal
// impulse and ut its tangential part, t = ut / |ut| and
//     jt = min(|ut| / K(t), mu jn),   apply -jt t,
// which stops the sliding if the Coulomb cone allows and never adds energy.
//
// Lanes where the contact separates or rests (vn >= 0), or where both bodies
// are immovable (K(n) = 0), keep their velocities bit for bit: every update is
// a select against the old value, never an addition of zero (x + 0 turns -0
// into +0). Immovable bodies (inverse mass 0) get inverse moments 0 here, so
// a caller's stale inverse moments cannot move them, and they are never
// written (see the driver in solve.cpp).
//
// Body models. The rigid model is the derivation above. The sphere model has
// Iw^-1 = s I, so h = r x d stays in the world frame and no rotation is
// formed; the particle model has no rotational term at all (and reads
// neither p nor w nor the contact point). Each model's terms are selected
// with `if constexpr` inside the one kernel body below, so the operations
// they share happen in the same order in all three.
//
// Precision: cancellation happens in u (the velocity terms may be large and
// nearly opposite) and in the lever arms h. The error of J is bounded by
// kImpulseErrorBoundEps * eps times the "impulse scale" that reference.hpp
// computes from both (plus friction and inherited terms), the figure the
// tests, `collide solve --check` and `collide report` measure against.
#pragma once

#include <limits>
#include <type_traits>
#include <utility>

#include "collide/bodies.hpp"
#include "exact_lanes.hpp"
#include "lanes.hpp"

namespace collide::detail {
inline namespace COLLIDE_KERNEL_NS {

struct ParticleModel {};
struct SphereModel {};
struct RigidModel {};

template <class M>
inline constexpr bool kRotates = !std::is_same_v<M, ParticleModel>;

/// How the law is evaluated (collide::Accuracy): FastMode in the lanes' own
/// precision, AccurateMode in the wider lanes of exact_lanes.hpp.
struct FastMode {};
struct AccurateMode {};

/// A rigid body's stored orientation (w, x, y, z), as read.
template <class V>
struct QuatLanes {
  V w, x, y, z;
};

/// The state of the W bodies on one side of W contacts, gathered into lanes.
/// Fields a model does not use are left unset and never read.
template <class M, class V>
struct BodyLanes {
  V inv_mass;           // [1/kg], 0 = immovable
  Vec3<V> inv_inertia;  // rigid: body frame [1/(kg m^2)]; sphere: x only
  Mat3<V> rotation;     // rigid: body to world, formed from q in the lanes' precision
  QuatLanes<V> q;       // rigid: as stored (the accurate mode forms its own rotation)
  Vec3<V> p;            // [m] (sphere, rigid)
  Vec3<V> v;            // [m/s]
  Vec3<V> w;            // [rad/s] (sphere, rigid)
};

/// Calls f(BodyFieldAt<View, K>{}) for every field K of the model of View (a
/// view or a packed record: collide/bodies.hpp's tables), unrolled at compile
/// time and forced inline like the rest of the kernel. BodyFieldAt::of
/// reaches the field's array in a view, its value in a record and its lane
/// in BodyLanes alike.
template <class View, class F, std::size_t... K>
COLLIDE_LANE_INLINE void each_lane_field(F& f, std::index_sequence<K...> /*fields*/) {
  (f(BodyFieldAt<View, K>{}), ...);
}
template <class View, class F>
COLLIDE_LANE_INLINE void for_each_lane_field(F&& f) {
  each_lane_field<View>(f, std::make_index_sequence<kFieldCount<View>>{});
}

/// The W contacts, gathered into lanes.
template <class V>
struct ContactLanes {
  Vec3<V> c;  // [m] (sphere, rigid)
  Vec3<V> n;  // unit, from b towards a
  V e;
  V mu;  // read only when the kernel runs with friction
};

/// What the kernel leaves in lanes, beyond the updated body velocities.
template <class V>
struct ContactResult {
  Vec3<V> j;  // total impulse on a [N s]
};

/// Immovable bodies have no rotational response either, whatever they store.
template <class M, class V>
COLLIDE_LANE_INLINE void zero_immovable_inertia(BodyLanes<M, V>& body) {
  const auto immovable = body.inv_mass == V(0);
  if constexpr (std::is_same_v<M, RigidModel>) {
    body.inv_inertia.x = select(immovable, V(0), body.inv_inertia.x);
    body.inv_inertia.y = select(immovable, V(0), body.inv_inertia.y);
    body.inv_inertia.z = select(immovable, V(0), body.inv_inertia.z);
  } else if constexpr (std::is_same_v<M, SphereModel>) {
    body.inv_inertia.x = select(immovable, V(0), body.inv_inertia.x);
  }
}

template <class V>
COLLIDE_LANE_INLINE Vec3<typename AccurateLanes<V>::type> widen(const Vec3<V>& v) {
  using A = AccurateLanes<V>;
  return {A::widen(v.x), A::widen(v.y), A::widen(v.z)};
}
template <class V, class W>
COLLIDE_LANE_INLINE Vec3<V> narrow(const Vec3<W>& w) {
  using A = AccurateLanes<V>;
  return {A::narrow(w.x), A::narrow(w.y), A::narrow(w.z)};
}

/// The rotation of q / |q|, as the law defines it: q is normalised here
/// (s = 2 / |q|^2), in the lanes' own precision in the fast mode and in the
/// wider lanes in the accurate mode, from the q the caller stored (any q the
/// input rules accept: |q|^2 a normal, finite number).
template <class W>
COLLIDE_LANE_INLINE Mat3<W> normalised_rotation(const QuatLanes<W>& q) {
  return rotation(q.w, q.x, q.y, q.z, W(2) / (((q.w * q.w + q.x * q.x) + q.y * q.y) + q.z * q.z));
}

/// The rigid float kernel forms its lever arms h = R^T (r x d) in double
/// lanes (fast mode; see lever_arm). Every other kernel works in its own lanes.
template <class M, class V>
inline constexpr bool kWideLeverArms =
    std::conjunction_v<std::is_same<M, RigidModel>, std::is_same<typename V::value_type, float>>;

/// h = R^T ((c - p) x d) of a rigid float body, evaluated in double lanes from
/// the stored c, p, q and d and rounded once to float. R^T x is applied as the
/// rotation by the conjugate of q, normalised as the law says:
///     R^T x = x + s (q_v x (q_v x x) - q_w (q_v x x)),   s = 2 / |q|^2,
/// which needs no matrix: computed from the float lanes at each use, it keeps
/// no double-lane state alive across the kernel (a double-lane matrix per body
/// spilled registers: docs/decisions/0009-the-fast-modes-lever-arms.md). In double lanes c - p
/// and every product of two floats are exact and every other rounding is
/// 2^-53, so h is the exact law's h rounded once to float
/// (docs/collision-law.md, "The lever arms").
template <class M, class V>
COLLIDE_LANE_INLINE Vec3<V> wide_lever(const BodyLanes<M, V>& body, const Vec3<V>& c, const Vec3<V>& d) {
  using A = AccurateLanes<V>;
  using W = typename A::type;
  const Vec3<W> x = cross(widen(c) - widen(body.p), widen(d));
  const Vec3<W> qv{A::widen(body.q.x), A::widen(body.q.y), A::widen(body.q.z)};
  const W qw = A::widen(body.q.w);
  const W s = W(2) / (((qw * qw + qv.x * qv.x) + qv.y * qv.y) + qv.z * qv.z);
  const Vec3<W> qx = cross(qv, x);
  return narrow<V>(x + (cross(qv, qx) - qx * qw) * s);
}

/// Relative velocity of a's contact point with respect to b's.
template <class M, class V>
COLLIDE_LANE_INLINE Vec3<V> relative_velocity(const BodyLanes<M, V>& a, const BodyLanes<M, V>& b, const Vec3<V>& ra,
                                              const Vec3<V>& rb) {
  if constexpr (kRotates<M>) {
    return (a.v + cross(a.w, ra)) - (b.v + cross(b.w, rb));
  } else {
    return a.v - b.v;
  }
}

/// One body's rotational share of K(d), and its angular response per unit
/// impulse along d, in the world frame: Iw^-1 (r x d) = R (invI * R^T (r x d))
/// (rigid), or invI (r x d) (sphere). Particles have neither.
template <class V>
struct LeverArm {
  Vec3<V> response;
  V k;
};

template <class M, class V>
COLLIDE_LANE_INLINE LeverArm<V> lever_arm(const BodyLanes<M, V>& body, const Vec3<V>& r, const Vec3<V>& d,
                                          const Vec3<V>& c) {
  // Filled member by member: GCC 12 copied a braced {response, k} through
  // general-purpose registers, 8 bytes at a time (store-forwarding stalls).
  if constexpr (std::is_same_v<M, ParticleModel>) return {};
  LeverArm<V> arm;
  if constexpr (std::is_same_v<M, RigidModel>) {
    // The float kernel's h in double lanes: a needle's tiny h along its axis
    // meets its huge inverse moment, a normal near r leaves |h| << |r|.
    Vec3<V> h;
    if constexpr (kWideLeverArms<M, V>) {
      (void)r;
      h = wide_lever(body, c, d);
    } else {
      (void)c;
      h = to_body(body.rotation, cross(r, d));
    }
    const Vec3<V> response = hadamard(body.inv_inertia, h);
    arm.response = to_world(body.rotation, response);
    arm.k = dot(h, response);
  } else if constexpr (std::is_same_v<M, SphereModel>) {
    (void)c;
    const Vec3<V> h = cross(r, d);
    arm.response = h * body.inv_inertia.x;
    arm.k = dot(h, arm.response);
  }
  return arm;
}

/// K(d) in the law's order: 1/ma + 1/mb + a's term + b's term.
template <class M, class V>
COLLIDE_LANE_INLINE V inverse_effective_mass(const BodyLanes<M, V>& a, const BodyLanes<M, V>& b,
                                             const LeverArm<V>& arm_a, const LeverArm<V>& arm_b) {
  if constexpr (kRotates<M>) {
    return ((a.inv_mass + b.inv_mass) + arm_a.k) + arm_b.k;
  } else {
    return a.inv_mass + b.inv_mass;
  }
}

/// Applies the impulse s * d to a (and -s * d to b) where `active`, given the
/// lever arms of d. Inactive lanes keep their velocities bit for bit.
template <class M, class V>
COLLIDE_LANE_INLINE void apply_impulse(BodyLanes<M, V>& a, BodyLanes<M, V>& b, const Vec3<V>& d, const V& s,
                                       const LeverArm<V>& arm_a, const LeverArm<V>& arm_b,
                                       const typename V::mask_type& active) {
  const Vec3<V> p = d * s;
  a.v = select(active, a.v + p * a.inv_mass, a.v);
  b.v = select(active, b.v - p * b.inv_mass, b.v);
  if constexpr (kRotates<M>) {
    a.w = select(active, a.w + arm_a.response * s, a.w);
    b.w = select(active, b.w - arm_b.response * s, b.w);
  }
}

/// |ut| and the direction of ut, for any finite ut. Squaring ut directly
/// would lose subnormal sliding speeds (in float, (1e-39)^2 is 0 and friction
/// vanished) and overflow above ~1e19. So ut is scaled by a power of two when
/// |ut|^2 leaves [2^-60, 2^60] (float; [2^-500, 2^500] in double): by 2^88
/// (2^600) below, by 2^-88 (2^-600) above, which brings every finite ut to
/// where its square neither underflows nor overflows. Scaling by a power of
/// two is exact, so a lane gets the same bits whether it was scaled or not,
/// and the choice is the lane's own (test_sliding_direction). Two selects
/// and a multiply, where dividing ut by its largest component would cost a
/// division per component.
template <class V>
struct SlidingDirection {
  Vec3<V> unit;     // ut times the scale (divide by scaled_length for t)
  V scaled_length;  // |ut| times the scale
  V speed;          // |ut| [m/s]
};

template <class T>
struct SlideScaling;
template <>
struct SlideScaling<float> {
  static constexpr float kLow = 0x1p-60f, kHigh = 0x1p60f, kUp = 0x1p88f, kDown = 0x1p-88f;
};
template <>
struct SlideScaling<double> {
  static constexpr double kLow = 0x1p-500, kHigh = 0x1p500, kUp = 0x1p600, kDown = 0x1p-600;
};

template <class V>
inline constexpr typename V::value_type kInfinity = std::numeric_limits<typename V::value_type>::infinity();

template <class V>
COLLIDE_LANE_INLINE SlidingDirection<V> sliding_direction(const Vec3<V>& ut) {
  using S = SlideScaling<typename V::value_type>;
  const V square = dot(ut, ut);
  const auto tiny = square < V(S::kLow);
  const auto huge = square > V(S::kHigh);  // inf included; NaN is neither
  const V scale = select(tiny, V(S::kUp), select(huge, V(S::kDown), V(1)));
  const V unscale = select(tiny, V(S::kDown), select(huge, V(S::kUp), V(1)));
  SlidingDirection<V> d;
  d.unit = ut * scale;
  d.scaled_length = lane_sqrt(dot(d.unit, d.unit));
  d.speed = d.scaled_length * unscale;
  return d;
}

/// The normal impulse of W contacts: which lanes act (approaching, K(n) > 0)
/// and jn there (0 elsewhere), and the approach speed vn = u . n it came
/// from (of the stored n in the fast mode), which the accumulated passes
/// keep for their restitution target.
template <class V>
struct NormalImpulse {
  typename V::mask_type approaching;
  V jn;
  V vn;
};

/// |n|^2 - 1 of a stored double normal, to about eps^2 (not eps): each
/// n_i^2 = p_i + e_i exactly (TwoProduct), the p_i summed with TwoSum and 1
/// subtracted from the sum, exactly for any n within 1/sqrt(2) .. sqrt(2) of
/// unit length (Sterbenz), which validate() and the CSV reader guarantee.
template <class V>
COLLIDE_LANE_INLINE V norm_excess(const Vec3<V>& n) {
  V px, ex, py, ey, pz, ez, s, t1, t2;
  two_product(n.x, n.x, px, ex);
  two_product(n.y, n.y, py, ey);
  two_product(n.z, n.z, pz, ez);
  two_sum(px, py, s, t1);
  two_sum(s, pz, s, t2);
  return (s - V(1)) + (((ex + ey) + ez) + (t1 + t2));
}

/// u . n of a particle contact (u = va - vb) in double, as hi + lo to about
/// eps^2 |u|: u_i = uh_i + ul_i exactly (TwoSum), uh_i n_i = p_i + e_i
/// exactly (TwoProduct), the p_i summed with TwoSum, and the small parts
/// (products, TwoSum errors, ul . n) added in plain double, then
/// renormalised, so hi carries the sign of the exact vn (Ogita, Rump and
/// Oishi's Dot2 on the six-term sum).
template <class V>
COLLIDE_LANE_INLINE void compensated_particle_vn(const Vec3<V>& va, const Vec3<V>& vb, const Vec3<V>& n, V& hi, V& lo) {
  V uhx, ulx, uhy, uly, uhz, ulz;
  two_sum(va.x, -vb.x, uhx, ulx);
  two_sum(va.y, -vb.y, uhy, uly);
  two_sum(va.z, -vb.z, uhz, ulz);
  V px, ex, py, ey, pz, ez, s, t1, t2;
  two_product(uhx, n.x, px, ex);
  two_product(uhy, n.y, py, ey);
  two_product(uhz, n.z, pz, ez);
  two_sum(px, py, s, t1);
  two_sum(s, pz, s, t2);
  const V small = (((ex + ey) + ez) + (t1 + t2)) + ((ulx * n.x + uly * n.y) + ulz * n.z);
  two_sum(s, small, hi, lo);
}

/// -(1 + e) (vh + vl) / (kh + kl), rounded once (to about eps^2 before
/// it): (1 + e) vh is formed exactly (FastTwoSum, TwoProduct), and the
/// quotient q1 = N * (1/kh) is corrected by the remainder N - q1 K, which
/// TwoProduct forms exactly, times 1/kh (one division in all). Lanes with
/// kh = 0 give inf or NaN, which the caller discards.
template <class V>
COLLIDE_LANE_INLINE V compensated_normal_impulse(const V& vh, const V& vl, const V& e, const V& kh, const V& kl) {
  V oh, ol, p, pe, ph, phe;
  fast_two_sum(V(1), e, oh, ol);  // 1 >= e >= 0
  two_product(oh, vh, p, pe);
  const V n_lo = pe + (oh * vl + ol * vh);
  const V inv = V(1) / kh;
  const V q1 = p * inv;
  two_product(q1, kh, ph, phe);
  const V r = (((p - ph) - phe) + n_lo) - q1 * kl;
  return -(q1 + r * inv);
}

/// The normal impulse in the fast mode. The law normalises n; the stored n
/// is the caller's, unit only within the input tolerance (collide/rules.hpp),
/// and the kernels take it as it is. The impulse
/// P = jn n is then the law's when jn = -(1 + e) (u . n) / D with
///     D = |n|^2 (1/ma + 1/mb) + ka(n) + kb(n)   (= |n|^2 K(n / |n|)),
/// since the lever terms ka, kb, computed from the stored n, already carry
/// |n|^2. Taking |n| = 1 instead scaled every impulse by |n|^2, up to 1.5
/// eps-units on its own, and a chain of contacts along one normal (a
/// Newton's cradle) passed the factor down every link
/// (docs/collision-law.md, "The normal impulse in the fast mode").
///   * float: |n|^2, the sum D and the quotient are formed in double lanes
///     and jn rounded once; the particle model's u . n too (va - vb and
///     its products with n are exact there);
///   * double: |n|^2 - 1 to eps^2 (norm_excess) corrects D; the particle
///     model forms u . n and the quotient compensated
///     (compensated_particle_vn, compensated_normal_impulse), so that its
///     jn is rounded once; the rigid and sphere models divide in double.
/// The particle model's error is then one rounding of jn and one of
/// J = jn n: taking the normal as unit, vn rounded and the quotient rounded
/// each cost up to 1.5 to 1.8 eps-units alone (tests/hard/hard_attribution.cpp).
template <class M, class V>
COLLIDE_LANE_INLINE NormalImpulse<V> fast_normal_impulse(const BodyLanes<M, V>& a, const BodyLanes<M, V>& b,
                                                         const Vec3<V>& u, const Vec3<V>& n, const V& e,
                                                         const LeverArm<V>& arm_a, const LeverArm<V>& arm_b) {
  using T = typename V::value_type;
  NormalImpulse<V> r;
  const V k_n = inverse_effective_mass(a, b, arm_a, arm_b);
  if constexpr (std::is_same_v<T, float>) {
    using A = AccurateLanes<V>;
    using W = typename A::type;
    const Vec3<W> nw = widen(n);
    W vn_w;
    V vn;
    if constexpr (kRotates<M>) {
      vn = dot(u, n);
      vn_w = A::widen(vn);
    } else {
      (void)u;
      vn_w = dot(widen(a.v) - widen(b.v), nw);
      vn = A::narrow(vn_w);  // keeps the sign; a vn that narrows to 0 has an impulse below the floor
    }
    W d = (A::widen(a.inv_mass) + A::widen(b.inv_mass)) * dot(nw, nw);
    if constexpr (kRotates<M>) d = (d + A::widen(arm_a.k)) + A::widen(arm_b.k);
    r.approaching = (vn < V(0)) && (k_n > V(0));
    r.vn = vn;
    // Inactive lanes may divide by zero here; their result is discarded.
    r.jn = select(r.approaching, A::narrow(-((W(1) + A::widen(e)) * vn_w) / d), V(0));
  } else {
    const V excess = norm_excess(n);
    if constexpr (kRotates<M>) {
      const V vn = dot(u, n);
      const V d = k_n + (a.inv_mass + b.inv_mass) * excess;
      r.approaching = (vn < V(0)) && (k_n > V(0));
      r.vn = vn;
      r.jn = select(r.approaching, -((V(1) + e) * vn) / d, V(0));
    } else {
      (void)u;
      V vh, vl, kh, kl;
      compensated_particle_vn(a.v, b.v, n, vh, vl);
      two_sum(a.inv_mass, b.inv_mass, kh, kl);
      V dh, dl;
      fast_two_sum(kh, kl + kh * excess, dh, dl);  // |kh| >= |kl + kh excess|
      r.approaching = (vh < V(0)) && (k_n > V(0));
      r.vn = vh;
      r.jn = select(r.approaching, compensated_normal_impulse(vh, vl, e, dh, dl), V(0));
    }
  }
  return r;
}

// The law in two halves
// ----------------------
// What the law needs of a contact splits into a velocity-free part, its
// geometry (the offsets, the lever arms along n and their K terms: most of
// the arithmetic, and all of the float kernel's double-lane work), and the
// velocity step (the normal impulse, its application and the Coulomb step),
// which reads the velocities the earlier contacts left. Every kernel
// composes the two: the lanes form both at once (evaluate_law), a run of
// contacts applied one after another forms the geometry in lanes and then
// steps the contacts one by one (kernel/loops.hpp, piece_walk). No contact of a
// solve changes a position or an orientation, so the geometry may be formed
// before the contacts ahead of it are stepped; either way the operations on
// every value are the same.

/// The velocity-free half of the law for W contacts.
template <class V>
struct ContactGeometry {
  Vec3<V> ra;  // [m] c - pa (sphere, rigid)
  Vec3<V> rb;  // [m] c - pb
  LeverArm<V> arm_a;
  LeverArm<V> arm_b;
};

/// Forms the geometry of W contacts; zeroes immovable bodies' inverse moments
/// first, as the law does.
template <class M, class V>
COLLIDE_LANE_INLINE ContactGeometry<V> contact_geometry(BodyLanes<M, V>& a, BodyLanes<M, V>& b,
                                                        const ContactLanes<V>& contact) {
  zero_immovable_inertia(a);
  zero_immovable_inertia(b);
  ContactGeometry<V> g{};
  if constexpr (kRotates<M>) {
    g.ra = contact.c - a.p;
    g.rb = contact.c - b.p;
  }
  g.arm_a = lever_arm(a, g.ra, contact.n, contact.c);
  g.arm_b = lever_arm(b, g.rb, contact.n, contact.c);
  return g;
}

/// The normal impulse of W contacts from their geometry and the bodies'
/// velocities now, in the mode `Mode`.
template <class M, class V, class Mode>
COLLIDE_LANE_INLINE NormalImpulse<V> normal_impulse(const BodyLanes<M, V>& a, const BodyLanes<M, V>& b,
                                                    const ContactLanes<V>& contact, const ContactGeometry<V>& g) {
  const Vec3<V>& n = contact.n;
  Vec3<V> u{};
  if constexpr (kRotates<M> || std::is_same_v<Mode, AccurateMode>) u = relative_velocity(a, b, g.ra, g.rb);
  NormalImpulse<V> normal;
  if constexpr (std::is_same_v<Mode, FastMode>) {
    normal = fast_normal_impulse(a, b, u, n, contact.e, g.arm_a, g.arm_b);
  } else {
    // The accurate mode's lanes carry n normalised and every digit needed.
    const V vn = dot(u, n);
    const V k_n = inverse_effective_mass(a, b, g.arm_a, g.arm_b);
    normal.approaching = (vn < V(0)) && (k_n > V(0));
    normal.vn = vn;
    // Inactive lanes may divide by zero here; their result is discarded.
    normal.jn = select(normal.approaching, -((V(1) + contact.e) * vn) / k_n, V(0));
  }
  return normal;
}

/// The Coulomb step of W contacts after their normal impulse (jn, applied
/// where `approaching`): stops the sliding where the cone allows, and adds
/// the friction impulse to `j`. Reads the bodies' velocities and, for the
/// lever arms along the sliding direction, their geometry. With `taken`,
/// leaves there the impulse taken from a, jt t (0 where nothing slides): the
/// first accumulated pass's friction total.
template <class M, class V, class Mode>
COLLIDE_LANE_INLINE void coulomb_step(BodyLanes<M, V>& a, BodyLanes<M, V>& b, const ContactLanes<V>& contact,
                                      const ContactGeometry<V>& g, const NormalImpulse<V>& normal, Vec3<V>& j,
                                      Vec3<V>* taken = nullptr) {
  const Vec3<V>& n = contact.n;
  const auto may_slide = normal.approaching && (contact.mu > V(0));
  if (!stdx::any_of(may_slide)) return;
  const Vec3<V> u_after = relative_velocity(a, b, g.ra, g.rb);
  // The tangential part of u' about the law's unit normal n / |n|. The
  // accurate mode's n is unit in its wider lanes; the fast mode's is the
  // caller's, unit within the input tolerance, so its projection divides by
  // |n|^2 (taking |n| = 1 would leave a normal component of (|n|^2 - 1) u'.n
  // in ut, up to 2e-3 of it).
  Vec3<V> ut;
  if constexpr (std::is_same_v<Mode, FastMode>) {
    ut = u_after - n * (dot(u_after, n) / dot(n, n));
  } else {
    ut = u_after - n * dot(u_after, n);
  }
  const SlidingDirection<V> slide = sliding_direction(ut);
  // Slides when ut is nonzero and every component finite (scaled, they are
  // at most 2^40); a NaN or inf component never slides. |ut| itself may
  // still overflow to inf, and then jt = mu jn.
  const auto sliding = may_slide && (slide.scaled_length > V(0)) && (slide.scaled_length < V(kInfinity<V>));
  const Vec3<V> t = slide.unit * (V(1) / select(sliding, slide.scaled_length, V(1)));
  const LeverArm<V> tarm_a = lever_arm(a, g.ra, t, contact.c);
  const LeverArm<V> tarm_b = lever_arm(b, g.rb, t, contact.c);
  const V k_t = inverse_effective_mass(a, b, tarm_a, tarm_b);
  // The Coulomb cap is mu times the law's normal impulse, |P| = |jn n|: jn
  // itself in the accurate mode (n unit), jn |n| in the fast mode.
  V cap = contact.mu * normal.jn;
  if constexpr (std::is_same_v<Mode, FastMode>) cap = cap * lane_sqrt(dot(n, n));
  const V jt = select(sliding, lane_min(slide.speed / k_t, cap), V(0));
  apply_impulse(a, b, t, -jt, tarm_a, tarm_b, sliding);
  const Vec3<V> friction = t * jt;
  j = select(sliding, j - friction, j);
  if (taken != nullptr) *taken = select(sliding, friction, Vec3<V>{V(0), V(0), V(0)});
}

/// The velocity step of W contacts whose bodies are pairwise distinct (or
/// immovable), given their geometry: the normal impulse applied, then, with
/// kFriction, the Coulomb step (without it `mu` is never read). Returns J.
template <class M, class V, bool kFriction, class Mode>
COLLIDE_LANE_INLINE ContactResult<V> velocity_step(BodyLanes<M, V>& a, BodyLanes<M, V>& b,
                                                   const ContactLanes<V>& contact, const ContactGeometry<V>& g) {
  const NormalImpulse<V> normal = normal_impulse<M, V, Mode>(a, b, contact, g);
  apply_impulse(a, b, contact.n, normal.jn, g.arm_a, g.arm_b, normal.approaching);
  ContactResult<V> result{contact.n * normal.jn};
  if constexpr (kFriction) coulomb_step<M, V, Mode>(a, b, contact, g, normal, result.j);
  return result;
}

/// The law for W contacts whose bodies are pairwise distinct (or immovable),
/// evaluated in the lanes V: the geometry, then the velocity step.
template <class M, class V, bool kFriction, class Mode>
COLLIDE_LANE_INLINE ContactResult<V> evaluate_law(BodyLanes<M, V>& a, BodyLanes<M, V>& b,
                                                  const ContactLanes<V>& contact) {
  const ContactGeometry<V> g = contact_geometry(a, b, contact);
  return velocity_step<M, V, kFriction, Mode>(a, b, contact, g);
}

/// One side's bodies in the accurate mode's lanes (exact: widening).
template <class M, class V>
COLLIDE_LANE_INLINE BodyLanes<M, typename AccurateLanes<V>::type> widen_body(const BodyLanes<M, V>& b) {
  using A = AccurateLanes<V>;
  BodyLanes<M, typename A::type> w;
  w.inv_mass = A::widen(b.inv_mass);
  w.v = widen(b.v);
  if constexpr (kRotates<M>) {
    w.p = widen(b.p);
    w.w = widen(b.w);
  }
  if constexpr (std::is_same_v<M, RigidModel>) {
    w.inv_inertia = widen(b.inv_inertia);
    w.rotation = normalised_rotation(
        QuatLanes<typename A::type>{A::widen(b.q.w), A::widen(b.q.x), A::widen(b.q.y), A::widen(b.q.z)});
  } else if constexpr (std::is_same_v<M, SphereModel>) {
    w.inv_inertia.x = A::widen(b.inv_inertia.x);
  }
  return w;
}

/// The law in the accurate mode: the same body (evaluate_law) run on the
/// wider lanes of exact_lanes.hpp - double lanes for float, double-double
/// for double - from the stored inputs with q and n normalised as the law
/// says, and every result rounded once to the stored precision. Every
/// cancellation the fast mode suffers (u and vn, the lever arms r x n and
/// R^T (r x n), friction's u' and ut) happens in the wider lanes, so J is
/// within about one rounding of the exact law (docs/collision-law.md,
/// "Accuracy modes"). Inactive lanes keep their bits: widening is exact and
/// narrowing a widened value returns it.
template <class M, class V, bool kFriction>
COLLIDE_LANE_INLINE ContactResult<V> evaluate_law_accurately(BodyLanes<M, V>& a, BodyLanes<M, V>& b,
                                                             const ContactLanes<V>& contact) {
  using A = AccurateLanes<V>;
  using W = typename A::type;
  BodyLanes<M, W> wa = widen_body(a);
  BodyLanes<M, W> wb = widen_body(b);
  ContactLanes<W> wc;
  if constexpr (kRotates<M>) wc.c = widen(contact.c);
  const Vec3<W> n = widen(contact.n);
  wc.n = n * (W(1) / lane_sqrt(dot(n, n)));
  wc.e = A::widen(contact.e);
  if constexpr (kFriction) wc.mu = A::widen(contact.mu);
  const ContactResult<W> r = evaluate_law<M, W, kFriction, AccurateMode>(wa, wb, wc);
  a.v = narrow<V>(wa.v);
  b.v = narrow<V>(wb.v);
  if constexpr (kRotates<M>) {
    a.w = narrow<V>(wa.w);
    b.w = narrow<V>(wb.w);
  }
  return ContactResult<V>{narrow<V>(r.j)};
}

/// The law's outputs, the new velocities and J, with every NaN made the
/// one NaN (canonical_nan in lanes.hpp): what every path writes.
template <class M, class V>
COLLIDE_LANE_INLINE void canonical_outputs(BodyLanes<M, V>& a, BodyLanes<M, V>& b, Vec3<V>& j) {
  const auto each = [](Vec3<V>& x) COLLIDE_LANE_LAMBDA {
    x = {canonical_nan(x.x), canonical_nan(x.y), canonical_nan(x.z)};
  };
  each(a.v);
  each(b.v);
  if constexpr (kRotates<M>) {
    each(a.w);
    each(b.w);
  }
  each(j);
}

/// J of the passes before plus this pass's (SolverOptions::passes), every
/// NaN the one NaN: the sum a caller would form of the passes' J in turn.
template <class V>
COLLIDE_LANE_INLINE Vec3<V> summed_impulse(const Vec3<V>& before, const Vec3<V>& j) {
  return {canonical_nan(before.x + j.x), canonical_nan(before.y + j.y), canonical_nan(before.z + j.z)};
}

/// evaluate_law_accurately, not inlined, for double: its double-double lanes
/// make that body several times the fast mode's, and inlined into every
/// caller (each model with and without friction, on each layout and body
/// stream) it made the largest functions of each kernel object's compile.
/// Each caller calls the one copy of its model and friction instead; against
/// the hundreds of double-double operations of a group, the call and the
/// lanes passed through memory cost little. The float kernel's wider lanes
/// are plain double, cheap enough that the call would show in its speed;
/// the compile times and the cost of the call:
/// docs/decisions/0032-the-double-accurate-law-out-of-line.md.
template <class M, class V, bool kFriction>
__attribute__((noinline)) ContactResult<V> evaluate_law_accurately_out_of_line(BodyLanes<M, V>& a, BodyLanes<M, V>& b,
                                                                               const ContactLanes<V>& contact) {
  return evaluate_law_accurately<M, V, kFriction>(a, b, contact);
}

/// The law for W contacts in the mode `Mode` (FastMode or AccurateMode).
template <class M, class V, bool kFriction, class Mode = FastMode>
COLLIDE_LANE_INLINE ContactResult<V> resolve_contacts(BodyLanes<M, V>& a, BodyLanes<M, V>& b,
                                                      const ContactLanes<V>& contact) {
  ContactResult<V> r;
  if constexpr (std::is_same_v<Mode, AccurateMode>) {
    if constexpr (std::is_same_v<typename V::value_type, double>) {
      r = evaluate_law_accurately_out_of_line<M, V, kFriction>(a, b, contact);
    } else {
      r = evaluate_law_accurately<M, V, kFriction>(a, b, contact);
    }
  } else {
    r = evaluate_law<M, V, kFriction, FastMode>(a, b, contact);
  }
  canonical_outputs(a, b, r.j);
  return r;
}

// The accumulated passes (Iteration::accumulate)
// -----------------------------------------------
// Sequential impulses with accumulated totals, as Box2D's b2SolveContact and
// Jolt's AxisConstraintPart iterate: each contact keeps its total normal
// impulse lambda (P = lambda n, n as stored) and its total friction impulse
// G (the impulse on a is -G), and a pass moves the totals instead of adding
// impulses that can never be taken back.
//
// The first pass is the law itself (resolve_contacts' operations, so one
// pass from zero is the repeat mode's bit for bit), and it records
//     lambda = jn,   G = jt t,   target = -e vn  (0 where the contact does not approach),
// vn the approach speed at the contact's first visit: restitution is asked
// for once, as a target normal velocity, not re-applied by every pass. A
// later pass, with D = |n|^2 (1/ma + 1/mb) + ka(n) + kb(n) as in the fast
// mode's normal impulse (so that u . n moves by D per unit of lambda),
//     lambda' = max(lambda + (target - u . n) / D, 0),   apply (lambda' - lambda) n,
// which can take back what the passes before gave too much; then, with
// friction, the impulse that would stop the sliding, |ut| / K(t) along t,
// is added to G and the sum clamped to the cone |G'| <= mu lambda' |n|:
//     G' = clamp(G + t |ut| / K(t)),   apply -(G' - G),
// along G' - G itself (its own lever arms). A lane whose totals do not move
// keeps its velocities bit for bit, as in the law.

/// The totals of W contacts between passes.
template <class V>
struct Accumulated {
  V normal;          // lambda: the normal impulse is lambda n [N s / |n|]
  V target;          // the u . n the passes drive towards [m/s |n|]
  Vec3<V> friction;  // G: the friction impulse on a is -G [N s]
};

/// The first accumulated pass of W contacts in the fast mode, given their
/// geometry: the law's velocity step (velocity_step), and the totals it
/// leaves in `acc`.
template <class M, class V, bool kFriction>
COLLIDE_LANE_INLINE ContactResult<V> first_accumulated_step(BodyLanes<M, V>& a, BodyLanes<M, V>& b,
                                                            const ContactLanes<V>& contact, const ContactGeometry<V>& g,
                                                            Accumulated<V>& acc) {
  const NormalImpulse<V> normal = normal_impulse<M, V, FastMode>(a, b, contact, g);
  apply_impulse(a, b, contact.n, normal.jn, g.arm_a, g.arm_b, normal.approaching);
  ContactResult<V> result{contact.n * normal.jn};
  acc.normal = normal.jn;
  acc.target = select(normal.approaching, V(0) - contact.e * normal.vn, V(0));
  acc.friction = {V(0), V(0), V(0)};
  if constexpr (kFriction) coulomb_step<M, V, FastMode>(a, b, contact, g, normal, result.j, &acc.friction);
  canonical_outputs(a, b, result.j);
  return result;
}

/// The friction part of a later accumulated pass: G moved by the impulse
/// that stops the sliding, clamped to the cone of the normal total.
template <class M, class V>
COLLIDE_LANE_INLINE void accumulated_coulomb_step(BodyLanes<M, V>& a, BodyLanes<M, V>& b,
                                                  const ContactLanes<V>& contact, const ContactGeometry<V>& g,
                                                  const typename V::mask_type& movable, Accumulated<V>& acc) {
  const Vec3<V>& n = contact.n;
  const auto may_slide = movable && (contact.mu > V(0));
  if (!stdx::any_of(may_slide)) return;
  const Vec3<V> u_after = relative_velocity(a, b, g.ra, g.rb);
  const Vec3<V> ut = u_after - n * (dot(u_after, n) / dot(n, n));
  const SlidingDirection<V> slide = sliding_direction(ut);
  const auto sliding = may_slide && (slide.scaled_length > V(0)) && (slide.scaled_length < V(kInfinity<V>));
  const Vec3<V> t = slide.unit * (V(1) / select(sliding, slide.scaled_length, V(1)));
  const LeverArm<V> tarm_a = lever_arm(a, g.ra, t, contact.c);
  const LeverArm<V> tarm_b = lever_arm(b, g.rb, t, contact.c);
  const V k_t = inverse_effective_mass(a, b, tarm_a, tarm_b);
  const V stop = select(sliding, slide.speed / k_t, V(0));
  const Vec3<V> wanted = acc.friction + t * stop;
  const V cap = (contact.mu * acc.normal) * lane_sqrt(dot(n, n));
  const V length = lane_sqrt(dot(wanted, wanted));
  // length > cap >= 0 never divides by zero; a NaN length keeps `wanted`.
  const V scale = select(length > cap, cap / select(length > cap, length, V(1)), V(1));
  const Vec3<V> friction = select(may_slide, wanted * scale, acc.friction);
  const Vec3<V> step = friction - acc.friction;
  const auto moves = may_slide && ((step.x != V(0)) || (step.y != V(0)) || (step.z != V(0)));
  const LeverArm<V> sarm_a = lever_arm(a, g.ra, step, contact.c);
  const LeverArm<V> sarm_b = lever_arm(b, g.rb, step, contact.c);
  apply_impulse(a, b, step, V(-1), sarm_a, sarm_b, moves);
  acc.friction = friction;
}

/// A later accumulated pass of W contacts in the fast mode, given their
/// geometry, from the totals in `acc`, which it moves.
template <class M, class V, bool kFriction>
COLLIDE_LANE_INLINE ContactResult<V> accumulated_step(BodyLanes<M, V>& a, BodyLanes<M, V>& b,
                                                      const ContactLanes<V>& contact, const ContactGeometry<V>& g,
                                                      Accumulated<V>& acc) {
  const Vec3<V>& n = contact.n;
  const V vn = dot(relative_velocity(a, b, g.ra, g.rb), n);
  const auto movable = inverse_effective_mass(a, b, g.arm_a, g.arm_b) > V(0);
  V d = (a.inv_mass + b.inv_mass) * dot(n, n);
  if constexpr (kRotates<M>) d = (d + g.arm_a.k) + g.arm_b.k;
  const V total = acc.normal + (acc.target - vn) / select(movable, d, V(1));
  // A NaN total compares false: the normal total drops to 0.
  const V normal = select(movable && (total > V(0)), total, V(0));
  const V step = normal - acc.normal;
  apply_impulse(a, b, n, step, g.arm_a, g.arm_b, movable && (step != V(0)));
  acc.normal = normal;
  if constexpr (kFriction) accumulated_coulomb_step(a, b, contact, g, movable, acc);
  ContactResult<V> result{n * acc.normal - acc.friction};
  canonical_outputs(a, b, result.j);
  return result;
}

/// The warm start of W contacts (SolverOptions::warm_start): two visits of
/// their own before the first accumulated pass, as Box2D stores each
/// contact's relative velocity when it prepares the contacts and warm-starts
/// all of them (b2WarmStartContactsTask) before its first iteration.
///
/// The first visit measures every target from the velocities the solve was
/// given, before any impulse: -e vn where the contact approaches, 0 where it
/// does not (or has no movable body). A resting contact that only its own
/// support holds up meets its bodies moving together and asks for no bounce.
///
/// The second applies the totals the caller's J gave, as the law applies an
/// impulse: lambda n along the normal's lever arms and, with friction, -G
/// along its own. Every contact's totals are on the bodies before any
/// contact steps, so no step sees a neighbour's support missing and undoes
/// its own. A contact without a movable body keeps no totals, as a pass
/// leaves it none.
template <class M, class V>
COLLIDE_LANE_INLINE void warm_start_target(const BodyLanes<M, V>& a, const BodyLanes<M, V>& b,
                                           const ContactLanes<V>& contact, const ContactGeometry<V>& g,
                                           Accumulated<V>& acc) {
  const V vn = dot(relative_velocity(a, b, g.ra, g.rb), contact.n);
  const auto movable = inverse_effective_mass(a, b, g.arm_a, g.arm_b) > V(0);
  acc.target = select(movable && (vn < V(0)), V(0) - contact.e * vn, V(0));
}

template <class M, class V, bool kFriction>
COLLIDE_LANE_INLINE void warm_start_step(BodyLanes<M, V>& a, BodyLanes<M, V>& b, const ContactLanes<V>& contact,
                                         const ContactGeometry<V>& g, Accumulated<V>& acc) {
  const auto movable = inverse_effective_mass(a, b, g.arm_a, g.arm_b) > V(0);
  acc.normal = select(movable, acc.normal, V(0));
  apply_impulse(a, b, contact.n, acc.normal, g.arm_a, g.arm_b, movable && (acc.normal != V(0)));
  if constexpr (kFriction) {
    const Vec3<V> zero{V(0), V(0), V(0)};
    acc.friction = select(movable, acc.friction, zero);
    const Vec3<V>& f = acc.friction;
    const auto moves = movable && ((f.x != V(0)) || (f.y != V(0)) || (f.z != V(0)));
    const LeverArm<V> farm_a = lever_arm(a, g.ra, f, contact.c);
    const LeverArm<V> farm_b = lever_arm(b, g.rb, f, contact.c);
    apply_impulse(a, b, f, V(-1), farm_a, farm_b, moves);
  }
  Vec3<V> none{V(0), V(0), V(0)};
  canonical_outputs(a, b, none);
}

/// The two accumulated passes with their geometry formed first (as
/// evaluate_law composes the law's halves).
template <class M, class V, bool kFriction>
COLLIDE_LANE_INLINE ContactResult<V> first_accumulated_pass(BodyLanes<M, V>& a, BodyLanes<M, V>& b,
                                                            const ContactLanes<V>& contact, Accumulated<V>& acc) {
  const ContactGeometry<V> g = contact_geometry(a, b, contact);
  return first_accumulated_step<M, V, kFriction>(a, b, contact, g, acc);
}
template <class M, class V, bool kFriction>
COLLIDE_LANE_INLINE ContactResult<V> accumulated_pass(BodyLanes<M, V>& a, BodyLanes<M, V>& b,
                                                      const ContactLanes<V>& contact, Accumulated<V>& acc) {
  const ContactGeometry<V> g = contact_geometry(a, b, contact);
  return accumulated_step<M, V, kFriction>(a, b, contact, g, acc);
}

}  // namespace COLLIDE_KERNEL_NS
}  // namespace collide::detail
