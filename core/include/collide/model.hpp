// collide/model.hpp - which body model a scene needs.
//
// A scene pays only for what it models. Three body models compute the law:
//
//   particle  inverse mass and v.                      K = 1/ma + 1/mb
//   sphere    + one inverse moment, p and w.           K += |ra x n|^2 / Ia + ...
//   rigid     + three inverse moments and q.           K += h . (invI * h), h = R^T (r x n)
//
// and friction is computed only when some contact has mu > 0. A smaller
// model computes the law *within its error bound* (accuracy.hpp, and the
// velocity bound of docs/collision-law.md) when the terms it leaves out are
// provably below kModelOmissionEps * eps(T) of the contact's impulse scale
// and of the velocity bound - a quarter of the bound's 64, so that rounding
// keeps three quarters (48 units, over four times the worst the hard cases
// measured). The derivation is in docs/collision-law.md, "Which body model
// computes the law"; the tests per rule:
//
//   * sphere fits when every movable body's inverse moments differ from the
//     one the kernel uses (x) by alpha <= kModelOmissionEps * eps relative to
//     the smallest, alpha / (1 - alpha) to be exact (equal moments: 0;
//     R diag(s, s, s) R^T = s I, orientation drops out);
//   * particle fits when every movable body has zero inverse moments and
//     every body zero angular velocity (no rotational term exists at all,
//     with or without friction), or when the scene is frictionless and every
//     contact has rho = sigma (1 + kappa) + kappa <= kModelOmissionEps * eps,
//     where sigma = |r x n| / |r| is the largest sine between the normal and
//     a lever arm of a body that spins or can rotate (it bounds the omitted
//     (w x r) . n against the speed scale and the omitted angular response
//     against the velocity bound) and kappa = sum max(invI) |r x n|^2 /
//     (1/ma + 1/mb) is the omitted share of K(n). A normal through both
//     centres (r x n = 0 exactly) gives rho = 0: the exact rule is the special
//     case. A broadphase's normals, normalised centre differences in the
//     scene's precision, miss the centres by a few eps and fit.
//
// Immovable bodies (inverse mass 0) never move, so their moments do not
// matter; their angular velocity does (a rotating kinematic body moves its
// contact point), and counts in sigma.
#pragma once

#include <string>

#include "collide/accuracy.hpp"
#include "collide/bodies.hpp"
#include "collide/contacts.hpp"

namespace collide {

/// The body model a kernel runs, cheapest first.
enum class Model { particle, sphere, rigid };

const char* to_string(Model model);

/// The omitted terms a smaller model may leave, in units of eps(T) of the
/// contact's impulse scale and velocity bound: a quarter of the bound.
inline constexpr double kModelOmissionEps = kImpulseErrorBoundEps / 4;

/// Why `model` does not give the law's result (within the error bound) for
/// the scene, or "" when it does. The message names the first body or contact that does not fit.
template <class T>
std::string model_misfit(Model model, const BodyView<T>& bodies, const ContactView<T>& contacts);

/// The cheapest model that gives the law's result for the scene, within the
/// error bound.
template <class T>
Model choose_model(const BodyView<T>& bodies, const ContactView<T>& contacts);

}  // namespace collide
