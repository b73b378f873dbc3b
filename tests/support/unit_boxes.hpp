// support/unit_boxes.hpp - scenes of unit boxes: a column stacked on an
// immovable ground, whose support impulses the passes must find
// (tests/core/test_iteration.cpp) and a warm start must keep
// (test_warm_start.cpp), and two boxes meeting head on, whose restitution
// both files check.
#pragma once

#include <cstddef>
#include <limits>

#include "collide/bodies.hpp"
#include "collide/contacts.hpp"
#include "collide/io/scene.hpp"

namespace collide::test {

/// A unit box (m = 1 kg, I = 1/6 kg m^2) at height y [m], moving at vy [m/s]
/// along y.
template <class T>
BodyRecord<T> box_at(T y, T vy) {
  BodyRecord<T> b;
  b.m = 1;
  b.I[0] = b.I[1] = b.I[2] = T(1) / 6;
  b.p[1] = y;
  b.v[1] = vy;
  return b;
}

/// An immovable box at height y [m], at rest.
template <class T>
BodyRecord<T> ground_at(T y) {
  BodyRecord<T> g = box_at<T>(y, 0);
  g.m = std::numeric_limits<T>::infinity();
  return g;
}

/// `boxes` unit boxes stacked on an immovable ground, every box falling at
/// `fall` [m/s] (one step of gravity): contact k joins box k (from the
/// bottom) to the box or the ground below it, at the middle of their shared
/// face, n = +y, e = 0. Contacts are listed top first, the order in which the
/// support converges slowest.
template <class T>
Scene<T> column(std::size_t boxes, T fall) {
  Scene<T> s;
  s.bodies.push_back(ground_at<T>(-0.5));
  for (std::size_t i = 0; i < boxes; ++i) s.bodies.push_back(box_at<T>(T(0.5) + T(i), -fall));
  for (std::size_t i = boxes; i-- > 0;) {
    ContactRecord<T> c;
    c.a = static_cast<BodyIndex>(i + 1);
    c.b = static_cast<BodyIndex>(i);
    c.c[1] = T(i);
    c.n[0] = 0;
    c.n[1] = 1;
    c.n[2] = 0;
    c.e = 0;
    s.contacts.push_back(c);
  }
  return s;
}

/// Two free unit boxes on the y axis, b at y = 0 and a at y = 1, meeting at
/// y = 0.5 with relative normal velocity `closing` [m/s] (< 0: approaching),
/// n = +y, restitution `e`.
template <class T>
Scene<T> head_on_pair(T closing, T e) {
  Scene<T> s;
  s.bodies.push_back(box_at<T>(0, -closing / 2));
  s.bodies.push_back(box_at<T>(1, closing / 2));
  ContactRecord<T> c;
  c.a = 1;
  c.b = 0;
  c.c[1] = T(0.5);
  c.n[0] = 0;
  c.n[1] = 1;
  c.n[2] = 0;
  c.e = e;
  s.contacts.push_back(c);
  return s;
}

}  // namespace collide::test
