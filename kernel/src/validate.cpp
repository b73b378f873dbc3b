// validate.cpp - the boundary checks of validate.hpp. One pass over every
// array, stopping at the first problem so the message can name one element.
#include "collide/validate.hpp"

#include <cmath>
#include <sstream>

namespace collide {
namespace {

constexpr double kUnitTolerance = 1e-4;

template <class T>
Validation fail(const char* view, const char* field, std::size_t i, T value, const char* what) {
  std::ostringstream s;
  s.precision(9);
  s << view << "." << field << "[" << i << "] = " << value << ": " << what;
  return {false, s.str()};
}

Validation fail_text(const std::string& text) { return {false, text}; }

}  // namespace

template <class T>
Validation validate(const BodyView<T>& bodies, const ContactView<T>& contacts, const ImpulseView<T>& impulses) {
  if (impulses.count != contacts.count) {
    return fail_text("impulses.count = " + std::to_string(impulses.count) +
                     " but contacts.count = " + std::to_string(contacts.count));
  }
  if (bodies.count > 0) {
    const T* arrays[] = {
        bodies.inv_mass, bodies.inv_inertia.x, bodies.inv_inertia.y, bodies.inv_inertia.z, bodies.q.w, bodies.q.x,
        bodies.q.y,      bodies.q.z,           bodies.p.x,           bodies.p.y,           bodies.p.z, bodies.v.x,
        bodies.v.y,      bodies.v.z,           bodies.w.x,           bodies.w.y,           bodies.w.z};
    for (const T* a : arrays) {
      if (a == nullptr) return fail_text("bodies: an array is null but bodies.count = " + std::to_string(bodies.count));
    }
  }
  if (contacts.count > 0) {
    if (!contacts.a || !contacts.b || !contacts.c.x || !contacts.c.y || !contacts.c.z || !contacts.n.x ||
        !contacts.n.y || !contacts.n.z) {
      return fail_text("contacts: an array is null but contacts.count = " + std::to_string(contacts.count));
    }
    if (!impulses.j.x || !impulses.j.y || !impulses.j.z) {
      return fail_text("impulses: an array is null but impulses.count = " + std::to_string(impulses.count));
    }
  }

  for (std::size_t i = 0; i < bodies.count; ++i) {
    const std::pair<const char*, const T*> inverse[] = {{"inv_mass", bodies.inv_mass},
                                                        {"inv_inertia.x", bodies.inv_inertia.x},
                                                        {"inv_inertia.y", bodies.inv_inertia.y},
                                                        {"inv_inertia.z", bodies.inv_inertia.z}};
    for (const auto& [name, a] : inverse) {
      if (!std::isfinite(a[i]) || a[i] < T(0)) return fail("bodies", name, i, a[i], "must be finite and >= 0");
    }
    const std::pair<const char*, const T*> finite[] = {
        {"q.w", bodies.q.w}, {"q.x", bodies.q.x}, {"q.y", bodies.q.y}, {"q.z", bodies.q.z}, {"p.x", bodies.p.x},
        {"p.y", bodies.p.y}, {"p.z", bodies.p.z}, {"v.x", bodies.v.x}, {"v.y", bodies.v.y}, {"v.z", bodies.v.z},
        {"w.x", bodies.w.x}, {"w.y", bodies.w.y}, {"w.z", bodies.w.z}};
    for (const auto& [name, a] : finite) {
      if (!std::isfinite(a[i])) return fail("bodies", name, i, a[i], "must be finite");
    }
    const double qn = std::sqrt(double(bodies.q.w[i]) * bodies.q.w[i] + double(bodies.q.x[i]) * bodies.q.x[i] +
                                double(bodies.q.y[i]) * bodies.q.y[i] + double(bodies.q.z[i]) * bodies.q.z[i]);
    if (std::abs(qn - 1.0) > kUnitTolerance) return fail("bodies", "|q|", i, qn, "must be 1 within 1e-4");
  }

  for (std::size_t k = 0; k < contacts.count; ++k) {
    if (contacts.a[k] >= bodies.count) {
      return fail("contacts", "a", k, contacts.a[k],
                  ("out of range (" + std::to_string(bodies.count) + " bodies)").c_str());
    }
    if (contacts.b[k] >= bodies.count) {
      return fail("contacts", "b", k, contacts.b[k],
                  ("out of range (" + std::to_string(bodies.count) + " bodies)").c_str());
    }
    if (contacts.a[k] == contacts.b[k])
      return fail("contacts", "b", k, contacts.b[k], "a contact of a body with itself");
    const std::pair<const char*, const T*> finite[] = {{"c.x", contacts.c.x}, {"c.y", contacts.c.y},
                                                       {"c.z", contacts.c.z}, {"n.x", contacts.n.x},
                                                       {"n.y", contacts.n.y}, {"n.z", contacts.n.z}};
    for (const auto& [name, a] : finite) {
      if (!std::isfinite(a[k])) return fail("contacts", name, k, a[k], "must be finite");
    }
    const double nn = std::sqrt(double(contacts.n.x[k]) * contacts.n.x[k] + double(contacts.n.y[k]) * contacts.n.y[k] +
                                double(contacts.n.z[k]) * contacts.n.z[k]);
    if (std::abs(nn - 1.0) > kUnitTolerance) return fail("contacts", "|n|", k, nn, "must be 1 within 1e-4");
    if (contacts.e && !(contacts.e[k] >= T(0) && contacts.e[k] <= T(1))) {
      return fail("contacts", "e", k, contacts.e[k], "must be in [0, 1]");
    }
    if (contacts.mu && !(std::isfinite(contacts.mu[k]) && contacts.mu[k] >= T(0))) {
      return fail("contacts", "mu", k, contacts.mu[k], "must be finite and >= 0");
    }
  }
  if (!contacts.e && !(contacts.uniform_e >= T(0) && contacts.uniform_e <= T(1))) {
    return fail("contacts", "uniform_e", 0, contacts.uniform_e, "must be in [0, 1]");
  }
  return {};
}

template Validation validate<float>(const BodyView<float>&, const ContactView<float>&, const ImpulseView<float>&);
template Validation validate<double>(const BodyView<double>&, const ContactView<double>&, const ImpulseView<double>&);

}  // namespace collide
