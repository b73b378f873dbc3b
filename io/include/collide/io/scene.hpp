// collide/io/scene.hpp - a scene: bodies and contacts together, and exact
// conversion between precisions.
#pragma once

#include <cstddef>
#include <type_traits>

#include "collide/bodies.hpp"
#include "collide/contacts.hpp"
#include "collide/io/scene_values.hpp"

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
// rounded once, as every route stores a scene value (scene_value,
// collide/io/scene_values.hpp), nothing renormalised, so the stored values
// are exactly what the kernel and the reference then read, and what the
// scene's files give. The generators (io/generate.hpp) and the hard scenes
// (eval/hard_scenes.hpp) draw in double. A float record (U = float) is
// widened exactly first: narrow<double> of a float record widens it.
namespace collide::detail {

template <class T, class U = double>
BodyRecord<T> narrow(const BodyRecord<U>& r) {
  static_assert(std::is_same_v<U, double> || std::is_same_v<U, float>, "records of scene values: double or float");
  BodyRecord<T> o;
  o.m = scene_value<T>(r.m);
  for (int k = 0; k < 3; ++k) {
    o.I[k] = scene_value<T>(r.I[k]);
    o.p[k] = scene_value<T>(r.p[k]);
    o.v[k] = scene_value<T>(r.v[k]);
    o.w[k] = scene_value<T>(r.w[k]);
  }
  for (int k = 0; k < 4; ++k) o.q[k] = scene_value<T>(r.q[k]);
  return o;
}

template <class T, class U = double>
ContactRecord<T> narrow(const ContactRecord<U>& r) {
  static_assert(std::is_same_v<U, double> || std::is_same_v<U, float>, "records of scene values: double or float");
  ContactRecord<T> o;
  o.a = r.a;
  o.b = r.b;
  for (int k = 0; k < 3; ++k) {
    o.c[k] = scene_value<T>(r.c[k]);
    o.n[k] = scene_value<T>(r.n[k]);
  }
  o.e = scene_value<T>(r.e);
  o.mu = scene_value<T>(r.mu);
  return o;
}

}  // namespace collide::detail
