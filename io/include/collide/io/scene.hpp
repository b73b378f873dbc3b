// collide/io/scene.hpp - a scene: bodies and contacts together, and exact
// conversion between precisions.
#pragma once

#include <cstddef>

#include "collide/bodies.hpp"
#include "collide/contacts.hpp"

namespace collide {

/// Owning scene: the bodies and the contacts between them.
template <class T>
struct Scene {
  BodyBuffer<T> bodies;
  ContactBuffer<T> contacts;
};

/// Copies a body view into a buffer of another precision, field by field with
/// static_cast and no renormalisation, so that a float scene widened to long
/// double holds exactly the same values (the reference must see the inputs
/// the kernel saw).
template <class S, class U>
BodyBuffer<S> convert_bodies(const BodyView<U>& src) {
  BodyBuffer<S> out(src.count);
  BodyView<S> dst = out.view();
  for (std::size_t i = 0; i < src.count; ++i) {
    dst.inv_mass[i] = static_cast<S>(src.inv_mass[i]);
    dst.inv_inertia.x[i] = static_cast<S>(src.inv_inertia.x[i]);
    dst.inv_inertia.y[i] = static_cast<S>(src.inv_inertia.y[i]);
    dst.inv_inertia.z[i] = static_cast<S>(src.inv_inertia.z[i]);
    dst.q.w[i] = static_cast<S>(src.q.w[i]);
    dst.q.x[i] = static_cast<S>(src.q.x[i]);
    dst.q.y[i] = static_cast<S>(src.q.y[i]);
    dst.q.z[i] = static_cast<S>(src.q.z[i]);
    dst.p.x[i] = static_cast<S>(src.p.x[i]);
    dst.p.y[i] = static_cast<S>(src.p.y[i]);
    dst.p.z[i] = static_cast<S>(src.p.z[i]);
    dst.v.x[i] = static_cast<S>(src.v.x[i]);
    dst.v.y[i] = static_cast<S>(src.v.y[i]);
    dst.v.z[i] = static_cast<S>(src.v.z[i]);
    dst.w.x[i] = static_cast<S>(src.w.x[i]);
    dst.w.y[i] = static_cast<S>(src.w.y[i]);
    dst.w.z[i] = static_cast<S>(src.w.z[i]);
  }
  return out;
}

/// Copies a contact view into a buffer of another precision, exactly (no
/// renormalisation of n). A view without `e` gets uniform_e in every row; a
/// view without `mu` gets mu = 0.
template <class S, class U>
ContactBuffer<S> convert_contacts(const ContactView<U>& src) {
  ContactBuffer<S> out;
  out.assign_exact(src);
  return out;
}

/// Both of the above.
template <class S, class U>
Scene<S> convert_scene(const Scene<U>& src) {
  return Scene<S>{convert_bodies<S>(src.bodies.view()), convert_contacts<S>(src.contacts.view())};
}

}  // namespace collide

// A scene record drawn in double, stored in the scene's precision: each value
// rounded once by static_cast, nothing renormalised, so the stored values are
// exactly what the kernel and the reference then read. The generators
// (io/generate.hpp) and the hard scenes (eval/hard_scenes.hpp) draw in double.
// The same cast takes a record of any precision U to T: narrow<double> of a
// float record widens it, exactly.
namespace collide::detail {

template <class T, class U = double>
BodyRecord<T> narrow(const BodyRecord<U>& r) {
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

template <class T, class U = double>
ContactRecord<T> narrow(const ContactRecord<U>& r) {
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
