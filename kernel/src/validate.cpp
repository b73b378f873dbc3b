// validate.cpp - the boundary checks of validate.hpp. One pass over every
// array, stopping at the first problem so the message can name one element.
#include "collide/validate.hpp"

#include <cmath>
#include <sstream>
#include <vector>

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

/// The arrays of a body view, each with the rule it must obey.
template <class T>
struct BodyField {
  const char* name;
  const T* data;
  bool inverse;  // an inverse mass or moment: finite and >= 0; otherwise finite
};

template <class T>
std::vector<BodyField<T>> fields_of(const BodyView<T>& b) {
  return {{"inv_mass", b.inv_mass, true},
          {"inv_inertia.x", b.inv_inertia.x, true},
          {"inv_inertia.y", b.inv_inertia.y, true},
          {"inv_inertia.z", b.inv_inertia.z, true},
          {"q.w", b.q.w, false},
          {"q.x", b.q.x, false},
          {"q.y", b.q.y, false},
          {"q.z", b.q.z, false},
          {"p.x", b.p.x, false},
          {"p.y", b.p.y, false},
          {"p.z", b.p.z, false},
          {"v.x", b.v.x, false},
          {"v.y", b.v.y, false},
          {"v.z", b.v.z, false},
          {"w.x", b.w.x, false},
          {"w.y", b.w.y, false},
          {"w.z", b.w.z, false}};
}
template <class T>
std::vector<BodyField<T>> fields_of(const SphereView<T>& b) {
  return {{"inv_mass", b.inv_mass, true}, {"inv_inertia", b.inv_inertia, true},
          {"p.x", b.p.x, false},          {"p.y", b.p.y, false},
          {"p.z", b.p.z, false},          {"v.x", b.v.x, false},
          {"v.y", b.v.y, false},          {"v.z", b.v.z, false},
          {"w.x", b.w.x, false},          {"w.y", b.w.y, false},
          {"w.z", b.w.z, false}};
}
template <class T>
std::vector<BodyField<T>> fields_of(const ParticleView<T>& b) {
  return {{"inv_mass", b.inv_mass, true}, {"v.x", b.v.x, false}, {"v.y", b.v.y, false}, {"v.z", b.v.z, false}};
}

/// The unit quaternion of the rigid model; other models have none.
template <class T>
Validation check_orientation(const BodyView<T>& b, std::size_t i) {
  const double qn = std::sqrt(double(b.q.w[i]) * b.q.w[i] + double(b.q.x[i]) * b.q.x[i] + double(b.q.y[i]) * b.q.y[i] +
                              double(b.q.z[i]) * b.q.z[i]);
  if (std::abs(qn - 1.0) > kUnitTolerance) return fail("bodies", "|q|", i, qn, "must be 1 within 1e-4");
  return {};
}
template <class View>
Validation check_orientation(const View&, std::size_t) {
  return {};
}

}  // namespace

template <class T, class View>
Validation validate_any(const View& bodies, const ContactView<T>& contacts, const ImpulseView<T>& impulses,
                        bool needs_contact_point) {
  if (impulses.count != contacts.count) {
    return fail_text("impulses.count = " + std::to_string(impulses.count) +
                     " but contacts.count = " + std::to_string(contacts.count));
  }
  const std::vector<BodyField<T>> fields = fields_of(bodies);
  if (bodies.count > 0) {
    for (const BodyField<T>& f : fields) {
      if (f.data == nullptr) {
        return fail_text(std::string("bodies.") + f.name +
                         " is null but bodies.count = " + std::to_string(bodies.count));
      }
    }
  }
  if (contacts.count > 0) {
    const bool no_point = !contacts.c.x || !contacts.c.y || !contacts.c.z;
    if (!contacts.a || !contacts.b || (needs_contact_point && no_point) || !contacts.n.x || !contacts.n.y ||
        !contacts.n.z) {
      return fail_text("contacts: an array is null but contacts.count = " + std::to_string(contacts.count));
    }
    if (!impulses.j.x || !impulses.j.y || !impulses.j.z) {
      return fail_text("impulses: an array is null but impulses.count = " + std::to_string(impulses.count));
    }
  }

  for (std::size_t i = 0; i < bodies.count; ++i) {
    for (const BodyField<T>& f : fields) {
      const T x = f.data[i];
      if (f.inverse && (!std::isfinite(x) || x < T(0))) return fail("bodies", f.name, i, x, "must be finite and >= 0");
      if (!f.inverse && !std::isfinite(x)) return fail("bodies", f.name, i, x, "must be finite");
    }
    if (Validation v = check_orientation(bodies, i); !v) return v;
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
    if (contacts.a[k] == contacts.b[k]) {
      return fail("contacts", "b", k, contacts.b[k], "a contact of a body with itself");
    }
    const std::pair<const char*, const T*> finite[] = {{"c.x", contacts.c.x}, {"c.y", contacts.c.y},
                                                       {"c.z", contacts.c.z}, {"n.x", contacts.n.x},
                                                       {"n.y", contacts.n.y}, {"n.z", contacts.n.z}};
    for (const auto& [name, a] : finite) {
      if (a != nullptr && !std::isfinite(a[k])) return fail("contacts", name, k, a[k], "must be finite");
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

template <class T>
Validation validate(const BodyView<T>& bodies, const ContactView<T>& contacts, const ImpulseView<T>& impulses) {
  return validate_any<T>(bodies, contacts, impulses, true);
}
template <class T>
Validation validate(const SphereView<T>& bodies, const ContactView<T>& contacts, const ImpulseView<T>& impulses) {
  return validate_any<T>(bodies, contacts, impulses, true);
}
template <class T>
Validation validate(const ParticleView<T>& bodies, const ContactView<T>& contacts, const ImpulseView<T>& impulses) {
  return validate_any<T>(bodies, contacts, impulses, false);
}

Validation validate_indices(const BodyIndex* a, const BodyIndex* b, std::size_t count, std::size_t body_count) {
  for (std::size_t k = 0; k < count; ++k) {
    // One branch per contact on the common path: all three checks at once.
    if (a[k] < body_count && b[k] < body_count && a[k] != b[k]) continue;
    const std::string range = "out of range (" + std::to_string(body_count) + " bodies)";
    if (a[k] >= body_count) return fail("contacts", "a", k, a[k], range.c_str());
    if (b[k] >= body_count) return fail("contacts", "b", k, b[k], range.c_str());
    return fail("contacts", "b", k, b[k], "a contact of a body with itself");
  }
  return {};
}

#define COLLIDE_INSTANTIATE(T)                                                                         \
  template Validation validate<T>(const BodyView<T>&, const ContactView<T>&, const ImpulseView<T>&);   \
  template Validation validate<T>(const SphereView<T>&, const ContactView<T>&, const ImpulseView<T>&); \
  template Validation validate<T>(const ParticleView<T>&, const ContactView<T>&, const ImpulseView<T>&);
COLLIDE_INSTANTIATE(float)
COLLIDE_INSTANTIATE(double)
#undef COLLIDE_INSTANTIATE

}  // namespace collide
