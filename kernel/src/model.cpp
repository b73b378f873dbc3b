// model.cpp - which body model gives the law's result for a scene
// (the rules are stated in collide/model.hpp).
//
// One pass over the bodies and, for the particle model's second rule, one
// over the contacts. The checks are exact comparisons, not tolerances: a
// model is chosen only when the terms it leaves out are exactly zero in the
// stored data, so the automatic choice never changes what is computed beyond
// rounding.
#include "collide/model.hpp"

#include <string>

namespace collide {
namespace {

template <class T>
bool is_zero3(const T* x, const T* y, const T* z, std::size_t i) {
  return x[i] == T(0) && y[i] == T(0) && z[i] == T(0);
}

std::string body_message(std::size_t i, const char* what) { return "body " + std::to_string(i) + " " + what; }

// Particle rule 1: no rotational term exists anywhere.
template <class T>
std::string particle_points_misfit(const BodyView<T>& b) {
  for (std::size_t i = 0; i < b.count; ++i) {
    if (!is_zero3(b.w.x, b.w.y, b.w.z, i)) return body_message(i, "has a non-zero angular velocity");
    const bool movable = b.inv_mass[i] != T(0);
    if (movable && !is_zero3(b.inv_inertia.x, b.inv_inertia.y, b.inv_inertia.z, i)) {
      return body_message(i, "can rotate (finite moments of inertia)");
    }
  }
  return {};
}

// Particle rule 2: frictionless, and every normal through both centres.
template <class T>
std::string particle_central_misfit(const BodyView<T>& b, const ContactView<T>& c) {
  if (c.mu != nullptr) return "the scene has friction and its bodies can rotate";
  for (std::size_t k = 0; k < c.count; ++k) {
    for (const BodyIndex i : {c.a[k], c.b[k]}) {
      const T rx = c.c.x[k] - b.p.x[i];
      const T ry = c.c.y[k] - b.p.y[i];
      const T rz = c.c.z[k] - b.p.z[i];
      const T nx = c.n.x[k], ny = c.n.y[k], nz = c.n.z[k];
      if (ry * nz - rz * ny != T(0) || rz * nx - rx * nz != T(0) || rx * ny - ry * nx != T(0)) {
        return "contact " + std::to_string(k) + ": the normal does not pass through the centre of body " +
               std::to_string(i);
      }
    }
  }
  return {};
}

}  // namespace

const char* to_string(Model model) {
  switch (model) {
    case Model::particle:
      return "particle";
    case Model::sphere:
      return "sphere";
    case Model::rigid:
      return "rigid";
  }
  return "?";
}

template <class T>
std::string model_misfit(Model model, const BodyView<T>& bodies, const ContactView<T>& contacts) {
  switch (model) {
    case Model::rigid:
      return {};
    case Model::sphere:
      for (std::size_t i = 0; i < bodies.count; ++i) {
        const bool movable = bodies.inv_mass[i] != T(0);
        if (movable && !(bodies.inv_inertia.x[i] == bodies.inv_inertia.y[i] &&
                         bodies.inv_inertia.y[i] == bodies.inv_inertia.z[i])) {
          return body_message(i, "has unequal principal moments of inertia");
        }
      }
      return {};
    case Model::particle: {
      std::string points = particle_points_misfit(bodies);
      if (points.empty()) return {};
      std::string central = particle_central_misfit(bodies, contacts);
      if (central.empty()) return {};
      return points + ", and " + central;
    }
  }
  return "unknown model";
}

template <class T>
Model choose_model(const BodyView<T>& bodies, const ContactView<T>& contacts) {
  if (model_misfit(Model::particle, bodies, contacts).empty()) return Model::particle;
  if (model_misfit(Model::sphere, bodies, contacts).empty()) return Model::sphere;
  return Model::rigid;
}

template std::string model_misfit<float>(Model, const BodyView<float>&, const ContactView<float>&);
template std::string model_misfit<double>(Model, const BodyView<double>&, const ContactView<double>&);
template Model choose_model<float>(const BodyView<float>&, const ContactView<float>&);
template Model choose_model<double>(const BodyView<double>&, const ContactView<double>&);

}  // namespace collide
