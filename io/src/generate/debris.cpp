// generate/debris.cpp - the "debris" scene of collide/io/generate.hpp: contacts
// between bodies picked at random, the immovable ground among them.
//
// Design notes
// ------------
// * A contact names its bodies by index and draws them again from their own
//   streams (draw_debris_body), so that contact k is a pure function of
//   (seed, contacts, k) like body i, and the two can be streamed apart.
// * The bodies are shared, so a contact cannot re-draw them until it
//   approaches: it re-draws its normal instead, and flips it towards the
//   approach.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "collide/io/generate.hpp"
#include "generate/draws.hpp"

namespace collide {
namespace {

std::size_t debris_movable_count(std::size_t contacts) {
  return contacts == 0 ? 0 : std::max<std::size_t>(2, contacts / 2);
}

/// Half size of the debris box: about one body per 8 m^3.
double debris_half_extent(std::size_t movable) {
  return std::cbrt(static_cast<double>(std::max<std::size_t>(movable, 1)));
}

using generate_detail::approach_speed;
using generate_detail::CounterRng;
using generate_detail::draw_movable_body;
using generate_detail::fit_model;
using generate_detail::kDebrisBodyStream;
using generate_detail::kDebrisContactStream;
using generate_detail::kMinApproachSpeed;
using generate_detail::store;
using generate_detail::store_ground;
using generate_detail::to_vec;
using generate_detail::uniform_vec;
using generate_detail::unit_vec;
using generate_detail::Vec3;

}  // namespace

std::size_t debris_body_count(std::size_t contacts) { return debris_movable_count(contacts) + 1; }

void draw_debris_body(const GenerateOptions& options, std::size_t contacts, std::uint64_t i, BodyRecord<double>& body) {
  const std::size_t movable = debris_movable_count(contacts);
  const double half = debris_half_extent(movable);
  if (i >= movable) {
    // The ground: immovable, at rest, just below the debris box.
    store_ground({0.0, -half - 1.0, 0.0}, body);
    return;
  }
  CounterRng rng(options.seed, kDebrisBodyStream, i);
  draw_movable_body(rng, half, body);
  fit_model(options.model, body);
}

void draw_debris_contact(const GenerateOptions& options, std::size_t contacts, std::uint64_t k,
                         ContactRecord<double>& contact) {
  const std::size_t movable = debris_movable_count(contacts);
  CounterRng rng(options.seed, kDebrisContactStream, k);
  contact.a = static_cast<BodyIndex>(rng.below(movable));
  if (k % 4 == 3) {
    contact.b = static_cast<BodyIndex>(movable);  // every fourth contact is with the ground
  } else {
    const auto other = static_cast<BodyIndex>(rng.below(movable - 1));
    contact.b = other >= contact.a ? other + 1 : other;  // distinct from a, uniform
  }
  BodyRecord<double> a, b;
  draw_debris_body(options, contacts, contact.a, a);
  draw_debris_body(options, contacts, contact.b, b);
  // The contact point lies within a unit box around a's centre.
  const Vec3 c = to_vec(a.p) + uniform_vec(rng, -1.0, 1.0);
  store(c, contact.c);
  // A random normal, flipped so that the initial state approaches; re-drawn
  // when nearly tangent so the approach survives rounding to float.
  for (;;) {
    Vec3 n = unit_vec(rng);
    const double vn = approach_speed(a, b, c, n);
    if (std::fabs(vn) > kMinApproachSpeed) {
      if (vn > 0) n = {-n.x, -n.y, -n.z};
      store(n, contact.n);
      break;
    }
  }
  contact.e = rng.uniform();
  const double mu = rng.uniform();
  contact.mu = options.friction ? mu : 0.0;
}

}  // namespace collide
