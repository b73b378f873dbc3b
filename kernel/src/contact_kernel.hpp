// contact_kernel.hpp - the collision law for W contacts at once, written once
// over a lane type and instantiated for the scalar path (W = 1) and the SIMD
// path (W = 8 float / 4 double with AVX2).
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
// is 1/m plus this term. Every term of K is a sum of non-negative products, so
// K has no cancellation: its relative error is a few eps whatever the
// geometry. The normal impulse that gives separation speed -e vn is
//     jn = -(1 + e) vn / K(n),
// and applying P = jn n changes
//     va += P / ma,   wa += R (invI * h_a) jn,   vb -= P / mb,   wb -= R (invI * h_b) jn.
// (R (invI * h) is Iw^-1 (r x n): the angular response, back in the world frame.)
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
// Precision: cancellation happens only in u (the velocity terms may be large
// and nearly opposite). The error of jn is bounded by a few eps times
// (1 + e) * (|va| + |wa||ra| + |vb| + |wb||rb|) / K(n), the "impulse scale"
// that reference.hpp computes and the tests and the report measure against.
#pragma once

#include "lanes.hpp"

namespace collide::detail {

/// The state of the W bodies on one side of W contacts, gathered into lanes.
template <class V>
struct BodyLanes {
  V inv_mass;          // [1/kg], 0 = immovable
  Vec3<V> inv_inertia; // body frame [1/(kg m^2)]
  Mat3<V> rotation;    // body to world
  Vec3<V> p;           // [m]
  Vec3<V> v;           // [m/s]
  Vec3<V> w;           // [rad/s]
};

/// The W contacts, gathered into lanes.
template <class V>
struct ContactLanes {
  Vec3<V> c;  // [m]
  Vec3<V> n;  // unit, from b towards a
  V e;
  V mu;       // read only when the kernel runs with friction
};

/// What the kernel leaves in lanes, beyond the updated body velocities.
template <class V>
struct ContactResult {
  Vec3<V> j;  // total impulse on a [N s]
};

/// Immovable bodies have no rotational response either, whatever they store.
template <class V>
COLLIDE_LANE_INLINE void zero_immovable_inertia(BodyLanes<V>& body) {
  const auto immovable = body.inv_mass == V(0);
  stdx::where(immovable, body.inv_inertia.x) = V(0);
  stdx::where(immovable, body.inv_inertia.y) = V(0);
  stdx::where(immovable, body.inv_inertia.z) = V(0);
}

/// Relative velocity of a's contact point with respect to b's.
template <class V>
COLLIDE_LANE_INLINE Vec3<V> relative_velocity(const BodyLanes<V>& a, const BodyLanes<V>& b, const Vec3<V>& ra,
                                 const Vec3<V>& rb) {
  return (a.v + cross(a.w, ra)) - (b.v + cross(b.w, rb));
}

/// One body's rotational share of K(d), and invI * h for applying the impulse.
template <class V>
struct LeverArm {
  Vec3<V> response;  // invI * R^T (r x d), body frame
  V k;               // h . (invI * h)
};

template <class V>
COLLIDE_LANE_INLINE LeverArm<V> lever_arm(const BodyLanes<V>& body, const Vec3<V>& r, const Vec3<V>& d) {
  const Vec3<V> h = to_body(body.rotation, cross(r, d));
  const Vec3<V> response = hadamard(body.inv_inertia, h);
  return {response, dot(h, response)};
}

/// Applies the impulse s * d to a (and -s * d to b) where `active`, given the
/// lever arms of d. Inactive lanes keep their velocities bit for bit.
template <class V>
COLLIDE_LANE_INLINE void apply_impulse(BodyLanes<V>& a, BodyLanes<V>& b, const Vec3<V>& d, const V& s, const LeverArm<V>& arm_a,
                          const LeverArm<V>& arm_b, const typename V::mask_type& active) {
  const Vec3<V> p = d * s;
  a.v = select(active, a.v + p * a.inv_mass, a.v);
  b.v = select(active, b.v - p * b.inv_mass, b.v);
  a.w = select(active, a.w + to_world(a.rotation, arm_a.response * s), a.w);
  b.w = select(active, b.w - to_world(b.rotation, arm_b.response * s), b.w);
}

/// The law for W contacts whose bodies are pairwise distinct (or immovable).
/// kFriction selects the Coulomb step; without it `mu` is never read.
template <class V, bool kFriction>
COLLIDE_LANE_INLINE ContactResult<V> resolve_contacts(BodyLanes<V>& a, BodyLanes<V>& b, const ContactLanes<V>& contact) {
  zero_immovable_inertia(a);
  zero_immovable_inertia(b);
  const Vec3<V>& n = contact.n;
  const Vec3<V> ra = contact.c - a.p;
  const Vec3<V> rb = contact.c - b.p;

  const V vn = dot(relative_velocity(a, b, ra, rb), n);
  const LeverArm<V> arm_a = lever_arm(a, ra, n);
  const LeverArm<V> arm_b = lever_arm(b, rb, n);
  // K(n) in the law's order: 1/ma + 1/mb + a's term + b's term.
  const V k_n = ((a.inv_mass + b.inv_mass) + arm_a.k) + arm_b.k;

  const auto approaching = (vn < V(0)) && (k_n > V(0));
  // Inactive lanes may divide by zero here; their result is discarded.
  const V jn = select(approaching, -((V(1) + contact.e) * vn) / k_n, V(0));
  apply_impulse(a, b, n, jn, arm_a, arm_b, approaching);

  ContactResult<V> result{n * jn};
  if constexpr (kFriction) {
    const auto may_slide = approaching && (contact.mu > V(0));
    if (stdx::any_of(may_slide)) {
      const Vec3<V> u = relative_velocity(a, b, ra, rb);
      const Vec3<V> ut = u - n * dot(u, n);
      const V ut_len = stdx::sqrt(dot(ut, ut));
      const auto sliding = may_slide && (ut_len > V(0));
      const V safe_len = select(sliding, ut_len, V(1));
      const Vec3<V> t{ut.x / safe_len, ut.y / safe_len, ut.z / safe_len};
      const LeverArm<V> tarm_a = lever_arm(a, ra, t);
      const LeverArm<V> tarm_b = lever_arm(b, rb, t);
      const V k_t = ((a.inv_mass + b.inv_mass) + tarm_a.k) + tarm_b.k;
      const V jt = select(sliding, stdx::min(ut_len / k_t, contact.mu * jn), V(0));
      apply_impulse(a, b, t, -jt, tarm_a, tarm_b, sliding);
      result.j = select(sliding, result.j - t * jt, result.j);
    }
  }
  return result;
}

}  // namespace collide::detail
