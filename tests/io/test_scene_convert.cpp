// test_scene_convert.cpp - the exact precision conversion of scenes
// (convert_scene, convert_bodies, convert_contacts in collide/io/scene.hpp).
//
// What this proves
// ----------------
// * convert_scene / convert_bodies / convert_contacts copy values exactly,
//   with no renormalisation: float -> long double -> float is the identity
//   bit for bit, a view without e gives uniform_e in every row, a view
//   without mu gives mu = 0.
// The buffers themselves are the core's (tests/core/test_buffers.cpp).
#include <cstddef>
#include <utility>

#include <gtest/gtest.h>

#include "collide/bodies.hpp"
#include "collide/contacts.hpp"
#include "collide/io/scene.hpp"
#include "support/scenes.hpp"
#include "support/solve_helpers.hpp"

namespace collide::test {
namespace {

TEST(SceneConversion, FloatToLongDoubleAndBackIsExact) {
  SceneOptions o;
  o.friction = true;
  const Scene<float> f = shared_scene<float>(500, 100, o);
  const Scene<long double> wide = convert_scene<long double>(f);
  const Scene<float> back = convert_scene<float>(wide);
  EXPECT_TRUE(same_bodies(f.bodies, back.bodies));
  const ContactView<float> x = f.contacts.view(), y = back.contacts.view();
  ASSERT_EQ(x.count, y.count);
  ASSERT_NE(y.mu, nullptr);
  for (std::size_t k = 0; k < x.count; ++k) {
    ASSERT_EQ(x.a[k], y.a[k]);
    ASSERT_EQ(x.b[k], y.b[k]);
    for (const auto& [p, q] :
         {std::pair{x.c.x, y.c.x}, std::pair{x.c.y, y.c.y}, std::pair{x.c.z, y.c.z}, std::pair{x.n.x, y.n.x},
          std::pair{x.n.y, y.n.y}, std::pair{x.n.z, y.n.z}, std::pair{x.e, y.e}, std::pair{x.mu, y.mu}}) {
      ASSERT_TRUE(same_bits(p[k], q[k])) << "contact " << k;
    }
  }
  // No renormalisation: the widened normal is the float normal exactly, even
  // though it is not unit to long double precision.
  const ContactView<long double> w = wide.contacts.view();
  for (std::size_t k = 0; k < x.count; ++k) EXPECT_EQ(w.n.x[k], static_cast<long double>(x.n.x[k]));
  // The widened q likewise.
  EXPECT_EQ(std::as_const(wide.bodies).view().q.w[3], static_cast<long double>(std::as_const(f.bodies).view().q.w[3]));
}

TEST(SceneConversion, UniformEAndMissingMuBecomeRows) {
  const Scene<double> s = pairs_scene<double>(10);
  ContactView<double> v = s.contacts.view();
  v.e = nullptr;
  v.uniform_e = 0.375;
  ASSERT_EQ(v.mu, nullptr);
  const ContactBuffer<long double> c = convert_contacts<long double>(v);
  const ContactView<long double> w = c.view();
  ASSERT_NE(w.e, nullptr);
  for (std::size_t k = 0; k < w.count; ++k) {
    EXPECT_EQ(w.e[k], 0.375L);
    EXPECT_EQ(c.record(k).mu, 0.0L);
  }
  EXPECT_EQ(w.mu, nullptr);
}

}  // namespace
}  // namespace collide::test
