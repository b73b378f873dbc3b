// narrow_records.hpp - a scene record drawn in double, stored in the scene's
// precision: each value rounded once by static_cast, nothing renormalised, so
// the stored values are exactly what the kernel and the reference then read.
// Used by the generators (generate.cpp) and the hard scenes (hard_scenes.cpp).
#pragma once

#include "collide/bodies.hpp"
#include "collide/contacts.hpp"

namespace collide::detail {

template <class T>
BodyRecord<T> narrow(const BodyRecord<double>& r) {
  BodyRecord<T> o;
  o.m = static_cast<T>(r.m);
  for (int k = 0; k < 3; ++k) {
    o.I[k] = static_cast<T>(r.I[k]);
    o.p[k] = static_cast<T>(r.p[k]);
    o.v[k] = static_cast<T>(r.v[k]);
    o.w[k] = static_cast<T>(r.w[k]);
  }
  for (int k = 0; k < 4; ++k) o.q[k] = static_cast<T>(r.q[k]);
  return o;
}

template <class T>
ContactRecord<T> narrow(const ContactRecord<double>& r) {
  ContactRecord<T> o;
  o.a = r.a;
  o.b = r.b;
  for (int k = 0; k < 3; ++k) {
    o.c[k] = static_cast<T>(r.c[k]);
    o.n[k] = static_cast<T>(r.n[k]);
  }
  o.e = static_cast<T>(r.e);
  o.mu = static_cast<T>(r.mu);
  return o;
}

}  // namespace collide::detail
