// collide/model.hpp - which body model a scene needs.
//
// A scene pays only for what it models. Three body models compute the law:
//
//   particle  inverse mass and v.                      K = 1/ma + 1/mb
//   sphere    + one inverse moment, p and w.           K += |ra x n|^2 / Ia + ...
//   rigid     + three inverse moments and q.           K += h . (invI * h), h = R^T (r x n)
//
// and friction is computed only when some contact has mu > 0. A model is the
// law's result for a scene exactly when the terms it leaves out are zero:
//
//   * sphere fits when every movable body has equal inverse moments
//     (R diag(s, s, s) R^T = s I, orientation drops out);
//   * particle fits when every movable body has zero inverse moments and
//     every body zero angular velocity (no rotational term exists at all,
//     with or without friction), or when the scene is frictionless and every
//     contact's normal passes through both centres of mass (ra x n = 0 and
//     rb x n = 0 exactly: then (w x r) . n = w . (r x n) = 0 and the
//     rotational response to the impulse is zero).
//
// Immovable bodies (inverse mass 0) never move, so their moments do not
// matter; their angular velocity does (a rotating kinematic body moves its
// contact point), and the particle model requires it to be zero.
#pragma once

#include <string>

#include "collide/bodies.hpp"
#include "collide/contacts.hpp"

namespace collide {

/// The body model a kernel runs, cheapest first.
enum class Model { particle, sphere, rigid };

const char* to_string(Model model);

/// Why `model` does not give the law's result for the scene, or "" when it
/// does. The message names the first body or contact that does not fit.
template <class T>
std::string model_misfit(Model model, const BodyView<T>& bodies, const ContactView<T>& contacts);

/// The cheapest model that gives the law's result for the scene.
template <class T>
Model choose_model(const BodyView<T>& bodies, const ContactView<T>& contacts);

}  // namespace collide
