// test_determinism.cpp - the solver's result does not depend on the path, the
// SIMD width, the thread count or the block size (solve.cpp).
//
// What this proves
// ----------------
// On random scenes - pairs (one contiguous batch; bodies read by vector loads
// and a deinterleave), pairs with a and b swapped (gathered), pairs with 10%
// immovable bodies (vector loads, scattered stores) and shared bodies (many
// gathered batches, one immovable ground in 25% of contacts) and chains
// (hundreds of batches of one or two contacts, which the driver runs as one
// stream on the one-lane kernel, between large batches) - in float and
// double, with and without friction, with per-contact e and with
// a uniform e (ContactView::e == nullptr):
// * the SIMD path and the scalar path give identical bytes for every J and
//   every body's v and w (and leave every other body field untouched);
// * thread counts 1, 2, 3 and 8 and blocks of 8, 64 and 4096 contacts give
//   identical bytes (a block of 8 forces tbb::parallel_for inside batches);
// * solving twice with the same Solver gives identical bytes.
// The TBB worker limit is raised to 8 for this test so that 3- and 8-thread
// arenas really run that many threads even on a 2-core machine.
#include <cstdint>
#include <limits>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <oneapi/tbb/global_control.h>

#include "collide/io/scene.hpp"
#include "collide/solve.hpp"
#include "support/sanitized.hpp"
#include "support/scenes.hpp"
#include "support/solve_helpers.hpp"

namespace collide::test {
namespace {

/// Scene layouts. The SIMD path has three ways to read bodies: vector loads
/// with a deinterleave when contact l of a group joins bodies first + 2l and
/// first + 2l + 1 (pairs), a gather otherwise (pairs with a and b swapped,
/// shared), and a scatter instead of an interleaved store when a group holds
/// an immovable body (pairs with some immovable bodies).
/// The chains run their runs of tiny batches on the one-lane kernel in one
/// call (solve.cpp), which must change nothing either.
enum class Layout { pairs, pairs_swapped, pairs_some_immovable, shared, chains };

struct Config {
  Layout layout;
  bool friction;
  bool uniform_e;
};

std::string describe(const Config& c) {
  const char* layout = c.layout == Layout::pairs                  ? "pairs"
                       : c.layout == Layout::pairs_swapped        ? "pairs-swapped"
                       : c.layout == Layout::pairs_some_immovable ? "pairs-some-immovable"
                       : c.layout == Layout::shared               ? "shared"
                                                                  : "chains";
  return std::string(layout) + (c.friction ? " friction" : " frictionless") +
         (c.uniform_e ? " uniform-e" : " per-contact-e");
}

void PrintTo(const Config& c, std::ostream* os) { *os << describe(c); }

template <class T>
Scene<T> build(const Config& cfg, const SceneOptions& o) {
  // Solved on every path, thread count, block and layout: the sweep's size
  // (support/sanitized.hpp); the chains' 1000 contacts stay whole.
  if (cfg.layout == Layout::shared) return shared_scene<T>(sweep_contacts(24000), sweep_contacts(8000), o);
  SceneRecords<T> r = pairs_records<T>(sweep_contacts(20000) + 3, o);
  Rng rng(o.seed + 1);
  for (std::size_t k = 0; k < r.contacts.size(); ++k) {
    ContactRecord<T>& c = r.contacts[k];
    if (cfg.layout == Layout::pairs_swapped) {
      std::swap(c.a, c.b);
      for (T& x : c.n) x = -x;  // still from b towards a
    } else if (cfg.layout == Layout::chains && k < 1000) {
      // Contacts 0..599 chain bodies 0..600, contacts 600..999 chain bodies
      // 1000..1400: levels 1..399 hold two contacts, 400..599 one, and the
      // pairs of those bodies come after, in later levels. A run of 1000
      // contacts, long enough for the SIMD path to form its geometry on a
      // second thread (run_pipeline.hpp, from 512 contacts).
      c.a = static_cast<BodyIndex>(k < 600 ? k : 400 + k);
      c.b = c.a + 1;
      make_approach(r.bodies[c.a], r.bodies[c.b], c);
    } else if (cfg.layout == Layout::pairs_some_immovable && rng.chance(0.1)) {
      BodyRecord<T>& b = r.bodies[rng.chance(0.5) ? c.a : c.b];
      b.m = std::numeric_limits<T>::infinity();
      make_approach(r.bodies[c.a], r.bodies[c.b], c);
    }
  }
  return r.scene();
}

template <class T>
void expect_deterministic(const Config& cfg, std::uint64_t seed) {
  SCOPED_TRACE(std::string(type_name<T>()) + " " + describe(cfg));
  SceneOptions o;
  o.seed = seed;
  o.friction = cfg.friction;
  const Scene<T> scene = build<T>(cfg, o);
  ContactView<T> view = scene.contacts.view();
  if (cfg.uniform_e) {
    view.e = nullptr;
    view.uniform_e = T(0.375);
  }
  ASSERT_EQ(view.mu != nullptr, cfg.friction);
  Schedule schedule;
  {
    BodyBuffer<T> b = scene.bodies;
    schedule.build(view, b.view());
  }
  if (cfg.layout == Layout::shared) {
    ASSERT_GT(schedule.batch_count(), 5u);
    ASSERT_GT(schedule.largest_batch(), sweep_contacts(1000));  // block = 8 really goes parallel
  }
  if (cfg.layout == Layout::chains) {
    ASSERT_GE(schedule.batch_count(), 600u);
    ASSERT_EQ(schedule.batch_begin(2) - schedule.batch_begin(1), 2u);  // runs of tiny batches...
    ASSERT_GT(schedule.largest_batch(), sweep_contacts(10000));        // ...after a large one
  }
  auto run = [&](const SolverOptions& options, BodyBuffer<T>& bodies, ImpulseBuffer<T>& j) {
    bodies = scene.bodies;
    j.resize(view.count);
    Solver(options).solve(bodies.view(), view, j.view(), schedule);
  };

  BodyBuffer<T> base_bodies;
  ImpulseBuffer<T> base_j;
  run(options_for(Path::scalar, 1), base_bodies, base_j);

  // Something happened: most impulses are non-zero.
  std::size_t acted = 0;
  for (std::size_t k = 0; k < base_j.size(); ++k) acted += base_j.view().j.x[k] != 0;
  EXPECT_GT(acted, view.count / 2);

  for (const Path path : {Path::scalar, Path::simd}) {
    for (const int threads : {1, 2, 3, 8}) {
      for (const std::size_t block : {std::size_t(8), std::size_t(64), std::size_t(4096)}) {
        SCOPED_TRACE(std::string(to_string(path)) + " threads " + std::to_string(threads) + " block " +
                     std::to_string(block));
        BodyBuffer<T> bodies;
        ImpulseBuffer<T> j;
        run(options_for(path, threads, block), bodies, j);
        EXPECT_TRUE(same_bodies(base_bodies, bodies));
        EXPECT_TRUE(same_impulses(base_j, j));
      }
    }
  }
  // Both layouts on the SIMD path: the automatic choice packs the chains,
  // whose run on SoA arrays forms its geometry on a second thread.
  for (const BodyLayout layout : {BodyLayout::soa, BodyLayout::packed}) {
    for (const int threads : {2, 3}) {
      SCOPED_TRACE(std::string(to_string(layout)) + " threads " + std::to_string(threads));
      SolverOptions options = options_for(Path::simd, threads, 64);
      options.layout = layout;
      BodyBuffer<T> bodies;
      ImpulseBuffer<T> j;
      run(options, bodies, j);
      EXPECT_TRUE(same_bodies(base_bodies, bodies));
      EXPECT_TRUE(same_impulses(base_j, j));
    }
  }

  // The same Solver twice.
  const Solver solver(options_for(Path::simd, 2, 64));
  BodyBuffer<T> first = scene.bodies, second = scene.bodies;
  ImpulseBuffer<T> j1(view.count), j2(view.count);
  solver.solve(first.view(), view, j1.view(), schedule);
  solver.solve(second.view(), view, j2.view(), schedule);
  EXPECT_TRUE(same_bodies(first, second));
  EXPECT_TRUE(same_impulses(j1, j2));
  EXPECT_TRUE(same_bodies(base_bodies, first));
}

class Determinism : public ::testing::TestWithParam<Config> {
 protected:
  // Lets arenas of 3 and 8 threads have their workers on small machines.
  tbb::global_control workers_{tbb::global_control::max_allowed_parallelism, 8};
};

TEST_P(Determinism, FloatIdenticalAcrossPathsThreadsAndBlocks) { expect_deterministic<float>(GetParam(), 101); }
TEST_P(Determinism, DoubleIdenticalAcrossPathsThreadsAndBlocks) { expect_deterministic<double>(GetParam(), 202); }

std::vector<Config> all_configs() {
  std::vector<Config> out;
  for (const Layout layout :
       {Layout::pairs, Layout::pairs_swapped, Layout::pairs_some_immovable, Layout::shared, Layout::chains}) {
    for (const bool friction : {false, true}) {
      for (const bool uniform_e : {false, true}) out.push_back({layout, friction, uniform_e});
    }
  }
  return out;
}

INSTANTIATE_TEST_SUITE_P(Scenes, Determinism, ::testing::ValuesIn(all_configs()),
                         [](const ::testing::TestParamInfo<Config>& info) {
                           std::string s = describe(info.param);
                           for (char& c : s) c = (c == ' ' || c == '-') ? '_' : c;
                           return s;
                         });

}  // namespace
}  // namespace collide::test
