// test_isa.cpp - one binary, every instruction set: the names and
// the choice of collide/isa.hpp, and the same bytes from every ISA this CPU
// has, on the pairs, debris, shared-body and hard scenes, for every model,
// precision and friction setting, on 1 and 2 threads.
#include <gtest/gtest.h>

#include <cstdlib>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "collide/eval/hard_scenes.hpp"
#include "collide/io/generate.hpp"
#include "collide/isa.hpp"
#include "collide/model.hpp"
#include "collide/schedule.hpp"
#include "collide/solve.hpp"
#include "support/isa_env.hpp"
#include "support/scenes.hpp"
#include "support/solve_helpers.hpp"

namespace collide::test {
namespace {

const Isa kConcrete[] = {Isa::sse2, Isa::avx2, Isa::avx512};

TEST(Isa, NamesRoundTrip) {
  for (const Isa isa : {Isa::automatic, Isa::sse2, Isa::avx2, Isa::avx512}) {
    EXPECT_EQ(parse_isa(to_string(isa)), isa);
  }
  EXPECT_THROW(parse_isa("avx"), std::invalid_argument);
  EXPECT_THROW(parse_isa(""), std::invalid_argument);
  EXPECT_THROW(parse_isa("AVX2"), std::invalid_argument);
  try {
    parse_isa("neon");
    FAIL() << "parse_isa accepted neon";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("neon"), std::string::npos) << e.what();
  }
}

TEST(Isa, TheBaselineAndTheBestAreSupported) {
  EXPECT_TRUE(isa_supported(Isa::sse2));
  EXPECT_TRUE(isa_supported(Isa::automatic));
  EXPECT_TRUE(isa_supported(best_isa()));
  EXPECT_NE(best_isa(), Isa::automatic);
#if defined(__x86_64__)
  // best_isa() agrees with the compiler's own CPU check.
  __builtin_cpu_init();
  const bool avx512 = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
                      __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512vl");
  // ... for the kernels this build has (COLLIDE_HAVE_KERNEL_*, from CMake).
#if defined(COLLIDE_HAVE_KERNEL_avx512)
  EXPECT_EQ(isa_supported(Isa::avx512), avx512);
#else
  EXPECT_FALSE(isa_supported(Isa::avx512));
#endif
#if defined(COLLIDE_HAVE_KERNEL_avx2)
  EXPECT_EQ(isa_supported(Isa::avx2), static_cast<bool>(__builtin_cpu_supports("avx2")));
#else
  EXPECT_FALSE(isa_supported(Isa::avx2));
#endif
#endif
}

TEST(Isa, EnvironmentChoosesTheDefault) {
  {
    const IsaEnv env(nullptr);
    EXPECT_EQ(default_isa(), best_isa());
    // Unset: a default Solver measures per solve (test_isa_auto.cpp).
    EXPECT_EQ(Solver().isa(), Isa::automatic);
    EXPECT_EQ(Solver().isa_choice(), IsaChoice::measured);
  }
  {
    const IsaEnv env("sse2");
    EXPECT_EQ(default_isa(), Isa::sse2);
    EXPECT_EQ(Solver().isa(), Isa::sse2);
    EXPECT_EQ(Solver().isa_choice(), IsaChoice::environment);
    // An explicit option wins over the environment.
    SolverOptions o;
    o.isa = best_isa();
    EXPECT_EQ(Solver(o).isa(), best_isa());
    EXPECT_EQ(Solver(o).isa_choice(), IsaChoice::forced);
  }
  {
    const IsaEnv env("auto");
    EXPECT_EQ(default_isa(), best_isa());
    EXPECT_EQ(Solver().isa_choice(), IsaChoice::measured);
  }
  {
    const IsaEnv env("avx3");
    EXPECT_THROW(default_isa(), std::invalid_argument);
    EXPECT_THROW(Solver(), std::invalid_argument);
  }
}

TEST(Isa, AnIsaTheCpuLacksIsAClearError) {
  for (const Isa isa : kConcrete) {
    SolverOptions o;
    o.isa = isa;
    if (isa_supported(isa)) {
      EXPECT_EQ(Solver(o).isa(), isa);
      continue;
    }
    try {
      const Solver s(o);
      FAIL() << "a Solver was built for " << to_string(isa) << " on a CPU without it";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(to_string(isa)), std::string::npos) << e.what();
    }
    const IsaEnv env(to_string(isa));
    EXPECT_THROW(default_isa(), std::invalid_argument);
  }
}

TEST(Isa, WidthsFollowTheIsa) {
  EXPECT_EQ(simd_width<float>(Isa::sse2), 4u);
  EXPECT_EQ(simd_width<double>(Isa::sse2), 2u);
  if (!isa_supported(Isa::avx2)) return;  // no AVX2 on this CPU, or no AVX2 kernel in this build
  EXPECT_EQ(simd_width<float>(Isa::avx2), 8u);
  EXPECT_EQ(simd_width<double>(Isa::avx2), 4u);
  if (isa_supported(Isa::avx512)) {
    EXPECT_EQ(simd_width<float>(Isa::avx512), 16u);
    EXPECT_EQ(simd_width<double>(Isa::avx512), 8u);
  }
}

/// Solves `scene` with `model` on the scalar path (1 thread) and on the SIMD
/// path of every ISA the CPU has (1 and 2 threads, blocks of 40 so that
/// blocks end mid-group and tails run), and compares every byte of v, w, J.
template <class T>
void expect_same_bytes_on_every_isa(const Scene<T>& scene, Model model, const std::string& what,
                                    BodyLayout layout = BodyLayout::automatic, Accuracy accuracy = Accuracy::fast) {
  SCOPED_TRACE(what + " " + type_name<T>() + " " + to_string(model) + " " + to_string(layout) + " " +
               to_string(accuracy));
  const ContactView<T> contacts = scene.contacts.view();
  Schedule schedule;
  {
    BodyBuffer<T> b = scene.bodies;
    schedule.build(contacts, b.view());
  }
  auto run = [&](const SolverOptions& o, BodyBuffer<T>& bodies, ImpulseBuffer<T>& j) {
    bodies = scene.bodies;
    j.resize(contacts.count);
    const SolveStats s = Solver(o).solve(model, bodies.view(), contacts, j.view(), schedule);
    return s;
  };
  BodyBuffer<T> base_bodies;
  ImpulseBuffer<T> base_j;
  SolverOptions scalar = options_for(Path::scalar, 1);
  scalar.accuracy = accuracy;
  run(scalar, base_bodies, base_j);
  std::size_t acted = 0;
  for (std::size_t k = 0; k < base_j.size(); ++k) acted += base_j.view().j.x[k] != 0;
  EXPECT_GT(acted, 0u) << "nothing happened: the comparison would prove little";

  int ran = 0;
  for (const Isa isa : kConcrete) {
    if (!isa_supported(isa)) continue;
    for (const int threads : {1, 2}) {
      SCOPED_TRACE(std::string(to_string(isa)) + " threads " + std::to_string(threads));
      SolverOptions o = options_for(Path::simd, threads, 40);
      o.isa = isa;
      o.layout = layout;
      o.accuracy = accuracy;
      BodyBuffer<T> bodies;
      ImpulseBuffer<T> j;
      const SolveStats s = run(o, bodies, j);
      EXPECT_EQ(s.isa, isa);
      EXPECT_EQ(s.lanes, simd_width<T>(isa));
      EXPECT_TRUE(same_bodies(base_bodies, bodies));
      EXPECT_TRUE(same_impulses(base_j, j));
      ++ran;
    }
  }
  EXPECT_GE(ran, 2);
}

template <class T>
void every_generated_scene() {
  for (const Model model : {Model::particle, Model::sphere, Model::rigid}) {
    for (const bool friction : {false, true}) {
      GenerateOptions g;
      g.seed = 7;
      g.friction = friction;
      g.model = model;
      const std::string f = friction ? " friction" : "";
      expect_same_bytes_on_every_isa(generate_pairs<T>(1003, g), model, "pairs" + f);
      expect_same_bytes_on_every_isa(generate_debris<T>(2005, g), model, "debris" + f);
    }
  }
}

TEST(IsaDispatch, GeneratedScenesFloat) { every_generated_scene<float>(); }
TEST(IsaDispatch, GeneratedScenesDouble) { every_generated_scene<double>(); }

template <class T>
void shared_and_hard_scenes() {
  SceneOptions o;
  o.friction = true;
  expect_same_bytes_on_every_isa(shared_scene<T>(3001, 300, o), Model::rigid, "shared");
  expect_same_bytes_on_every_isa(collide::hard::mass_ratio_family<T>(301, Model::rigid, 11).scene(), Model::rigid,
                                 "mass ratio");
  expect_same_bytes_on_every_isa(collide::hard::immovable_family<T>(301, Model::rigid, 12).scene(), Model::rigid,
                                 "immovable");
  expect_same_bytes_on_every_isa(collide::hard::needle_family<T>(301, 13).scene(), Model::rigid, "needle");
  expect_same_bytes_on_every_isa(collide::hard::long_lever_family<T>(301, Model::rigid, 14).scene(), Model::rigid,
                                 "lever");
  expect_same_bytes_on_every_isa(collide::hard::grazing_family<T>(301, Model::rigid, 15).scene(), Model::rigid,
                                 "grazing");
  expect_same_bytes_on_every_isa(collide::hard::unit_scale_family<T>(301, Model::rigid, 16).scene(), Model::rigid,
                                 "scales");
  expect_same_bytes_on_every_isa(collide::hard::subnormal_family<T>(301, Model::rigid, 17).scene(), Model::rigid,
                                 "subnormal");
}

/// Chains: runs of one-contact batches, which the SIMD path applies contact
/// after contact with lever arms formed in lanes (kernel/loops.hpp, run_loop).
/// 1037 contacts: pieces of 128 and groups of every width end mid-way. Every
/// 301st box is immovable (the run must neither move nor write it), in
/// both layouts, both modes, with and without friction (which, like the
/// accurate mode, runs on the one-lane kernel).
template <class T>
void chain_scenes() {
  for (const Model model : {Model::particle, Model::sphere, Model::rigid}) {
    for (const bool friction : {false, true}) {
      GenerateOptions g;
      g.seed = 9;
      g.friction = friction;
      g.model = model;
      Scene<T> chain = generate_chain<T>(1037, g);
      BodyView<T> b = chain.bodies.view();
      for (std::size_t i = 3; i < b.count; i += 301) b.inv_mass[i] = 0;
      // Spin and contact points off the centre lines, so that the lever arms
      // and the angular terms matter (particles have no spin: w stays 0).
      for (std::size_t i = 0; model != Model::particle && i < b.count; ++i) {
        b.w.x[i] = T(0.25) * static_cast<T>(i % 5);
        b.w.y[i] = T(-0.5) + T(0.125) * static_cast<T>(i % 3);
      }
      for (std::size_t k = 0; k < chain.contacts.size(); ++k) {
        ContactRecord<T> c = chain.contacts.record(k);
        c.c[2] += T(0.0625) * static_cast<T>(k % 7) - T(0.1875);
        chain.contacts.set(k, c);
      }
      // The solve asserts this in debug builds: the scene fits the model.
      ASSERT_EQ(model_misfit(model, chain.bodies.view(), chain.contacts.view()), "");
      for (const BodyLayout layout : {BodyLayout::soa, BodyLayout::packed}) {
        for (const Accuracy accuracy : {Accuracy::fast, Accuracy::accurate}) {
          expect_same_bytes_on_every_isa(chain, model, friction ? "chain friction" : "chain", layout, accuracy);
        }
      }
    }
  }
}

TEST(IsaDispatch, ChainsFloat) { chain_scenes<float>(); }
TEST(IsaDispatch, ChainsDouble) { chain_scenes<double>(); }

TEST(IsaDispatch, SharedAndHardScenesFloat) { shared_and_hard_scenes<float>(); }
TEST(IsaDispatch, SharedAndHardScenesDouble) { shared_and_hard_scenes<double>(); }

}  // namespace
}  // namespace collide::test
