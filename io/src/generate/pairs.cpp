// generate/pairs.cpp - the "pairs" scene of collide/io/generate.hpp:
// independent pairs, contact k joining bodies 2k and 2k+1.
//
// Design notes
// ------------
// * The page's own scene: each pair is drawn as its test program draws one,
//   and re-drawn in the same stream until it approaches, which only a scene
//   with no shared body can do (a debris or pile body's re-draw would move
//   its other contacts).
#include <cstdint>

#include "collide/io/generate.hpp"
#include "generate/draws.hpp"

namespace collide {
namespace {

using generate_detail::approach_speed;
using generate_detail::CounterRng;
using generate_detail::draw_movable_body;
using generate_detail::fit_model;
using generate_detail::kMinApproachSpeed;
using generate_detail::kPairStream;
using generate_detail::store;
using generate_detail::to_vec;
using generate_detail::uniform_vec;
using generate_detail::unit_vec;
using generate_detail::Vec3;

}  // namespace

void draw_pair(const GenerateOptions& options, std::uint64_t k, BodyRecord<double>& a, BodyRecord<double>& b,
               ContactRecord<double>& contact) {
  CounterRng rng(options.seed, kPairStream, k);
  contact.a = static_cast<BodyIndex>(2 * k);
  contact.b = static_cast<BodyIndex>(2 * k + 1);
  // Re-drawn until the pair approaches, as the page's program does (its
  // "goto START"); the draws go on in the same stream, about two attempts
  // on average.
  for (;;) {
    draw_movable_body(rng, 100.0, a);
    draw_movable_body(rng, 100.0, b);
    fit_model(options.model, a);
    fit_model(options.model, b);
    const Vec3 ra = uniform_vec(rng, -2.0, 2.0);
    const Vec3 rb = uniform_vec(rng, -2.0, 2.0);
    const Vec3 n = unit_vec(rng);
    const Vec3 c = to_vec(a.p) + ra;
    store(c, contact.c);
    store(c - rb, b.p);
    store(n, contact.n);
    contact.e = rng.uniform();
    const double mu = rng.uniform();
    contact.mu = options.friction ? mu : 0.0;
    if (approach_speed(a, b, c, n) < -kMinApproachSpeed) return;
  }
}

}  // namespace collide
