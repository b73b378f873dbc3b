// model.cpp - which body model gives the law's result for a scene, within
// the error bound (the rules are stated in collide/model.hpp and derived in
// docs/collision-law.md, "Which body model computes the law").
//
// One pass over the bodies (sphere) and one over the contacts (particle).
// The figures are computed from the stored data in a type wider than the
// kernel's (double for float, long double for double), so their own
// rounding is far below the threshold kModelOmissionEps * eps(T) they are
// compared with; an exact case (equal moments, a normal through both
// centres) gives exactly 0 and always fits.
#include "collide/model.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <type_traits>

namespace collide {
namespace {

/// The type the fit figures are evaluated in.
template <class T>
using Wider = std::conditional_t<std::is_same_v<T, float>, double, long double>;

template <class T>
bool is_zero3(const T* x, const T* y, const T* z, std::size_t i) {
  return x[i] == T(0) && y[i] == T(0) && z[i] == T(0);
}

std::string body_message(std::size_t i, const char* what) { return "body " + std::to_string(i) + " " + what; }

/// A figure in units of eps(T), for messages.
template <class T, class W>
std::string in_eps(W x) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.3g eps", static_cast<double>(x / W(std::numeric_limits<T>::epsilon())));
  return buf;
}

/// The threshold the omitted terms are held to: kModelOmissionEps * eps(T).
template <class T, class W>
W omission_threshold() {
  return W(kModelOmissionEps) * W(std::numeric_limits<T>::epsilon());
}

// Particle rule 1: no rotational term exists anywhere (exact; friction too).
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

/// The particle figure of one contact: rho = sigma (1 + kappa) + kappa with
/// sigma the largest |r x n| / |r| of a body that spins or can rotate and
/// kappa the rotational part of K(n) the model leaves out, relative to the
/// part it keeps (docs/collision-law.md). `worst` names the body that set
/// sigma.
template <class T>
Wider<T> particle_figure(const BodyView<T>& b, const ContactView<T>& c, std::size_t k, BodyIndex& worst) {
  using W = Wider<T>;
  const W nx = c.n.x[k], ny = c.n.y[k], nz = c.n.z[k];
  const W kp = W(b.inv_mass[c.a[k]]) + W(b.inv_mass[c.b[k]]);
  W sigma = 0;
  W rot_k = 0;
  worst = c.a[k];
  for (const BodyIndex i : {c.a[k], c.b[k]}) {
    const bool movable = b.inv_mass[i] != T(0);
    const bool rotates = movable && !is_zero3(b.inv_inertia.x, b.inv_inertia.y, b.inv_inertia.z, i);
    if (!rotates && is_zero3(b.w.x, b.w.y, b.w.z, i)) continue;
    const W rx = W(c.c.x[k]) - W(b.p.x[i]);
    const W ry = W(c.c.y[k]) - W(b.p.y[i]);
    const W rz = W(c.c.z[k]) - W(b.p.z[i]);
    const W hx = ry * nz - rz * ny, hy = rz * nx - rx * nz, hz = rx * ny - ry * nx;
    const W h2 = hx * hx + hy * hy + hz * hz;
    if (h2 == W(0)) continue;
    const W s = std::sqrt(h2 / (rx * rx + ry * ry + rz * rz));
    if (s > sigma) {
      sigma = s;
      worst = i;
    }
    if (rotates) {
      const W inv_i_max = std::max({W(b.inv_inertia.x[i]), W(b.inv_inertia.y[i]), W(b.inv_inertia.z[i])});
      rot_k += inv_i_max * h2;
    }
  }
  if (sigma == W(0) && rot_k == W(0)) return 0;  // the exact case: nothing is left out
  if (kp == W(0)) return 0;                      // both immovable: nothing happens (rot_k is 0 then too)
  const W kappa = rot_k / kp;
  return sigma * (W(1) + kappa) + kappa;
}

// Particle rule 2: frictionless, and every contact's omitted terms below the
// threshold.
template <class T>
std::string particle_central_misfit(const BodyView<T>& b, const ContactView<T>& c) {
  using W = Wider<T>;
  if (c.mu != nullptr) return "the scene has friction and its bodies can rotate";
  const W limit = omission_threshold<T, W>();
  for (std::size_t k = 0; k < c.count; ++k) {
    BodyIndex worst = 0;
    const W rho = particle_figure(b, c, k, worst);
    if (!(rho <= limit)) {
      return "contact " + std::to_string(k) + ": the normal does not pass through the centre of body " +
             std::to_string(worst) + " closely enough (omitted rotational terms " + in_eps<T>(rho) +
             " of the contact's scale, above the " + in_eps<T>(limit) + " the error bound allows)";
    }
  }
  return {};
}

/// alpha of one body: the largest difference of an inverse moment from the
/// one the sphere kernel uses (x), relative to the smallest inverse moment;
/// 0 when all three are equal, inf for a locked axis next to a free one.
template <class T>
Wider<T> sphere_alpha(const BodyView<T>& b, std::size_t i) {
  using W = Wider<T>;
  const W x = b.inv_inertia.x[i], y = b.inv_inertia.y[i], z = b.inv_inertia.z[i];
  if (x == y && y == z) return 0;
  const W lo = std::min({x, y, z});
  if (lo <= W(0)) return std::numeric_limits<W>::infinity();
  return std::max(std::abs(y - x), std::abs(z - x)) / lo;
}

/// The sphere figure: alpha / (1 - alpha) bounds the relative error of K
/// (and alpha that of the angular response).
template <class W>
W sphere_figure(W alpha) {
  return alpha < W(1) ? alpha / (W(1) - alpha) : std::numeric_limits<W>::infinity();
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
  using W = Wider<T>;
  switch (model) {
    case Model::rigid:
      return {};
    case Model::sphere: {
      const W limit = omission_threshold<T, W>();
      for (std::size_t i = 0; i < bodies.count; ++i) {
        if (bodies.inv_mass[i] == T(0)) continue;
        const W alpha = sphere_alpha(bodies, i);
        if (!(sphere_figure(alpha) <= limit)) {
          char spread[32];
          std::snprintf(spread, sizeof spread, "%.3g", static_cast<double>(alpha));
          return body_message(i, "has unequal principal moments of inertia") + " (relative spread of the inverse " +
                 "moments " + spread + ", above the " + in_eps<T>(limit) + " the error bound allows)";
        }
      }
      return {};
    }
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
