// test_packed.cpp - the packed body layout (collide/packed.hpp):
// conversions are exact, and solving on packed records - the caller's, or SoA
// input the solver packs - gives the same bits as the SoA arrays, for every
// model, precision, path, ISA and thread count, on pairs, debris, shared and
// hard scenes; the automatic choice packs scattered scenes and not streaming
// ones. (NaN/inf lane isolation on the packed layout: test_lane_isolation.)
#include <gtest/gtest.h>

#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "collide/eval/hard_scenes.hpp"
#include "collide/io/generate.hpp"
#include "collide/packed.hpp"
#include "collide/schedule.hpp"
#include "collide/solve.hpp"
#include "collide/validate.hpp"
#include "support/scenes.hpp"
#include "support/solve_helpers.hpp"

namespace collide::test {
namespace {

template <class Record>
bool same_record_bytes(const Record& x, const Record& y) {
  // Only the values: the padding of a record is not part of the layout.
  using T = typename PackedValue<Record>::type;
  constexpr std::size_t values = std::is_same_v<Record, PackedRigid<T>>    ? 16
                                 : std::is_same_v<Record, PackedSphere<T>> ? 11
                                                                           : 4;
  // The bits, on purpose: -0, NaN payloads and subnormals must survive.
  return std::memcmp(&x, &y, values * sizeof(T)) == 0;  // NOLINT(bugprone-suspicious-memory-comparison)
}

template <class T>
void expect_round_trip() {
  GenerateOptions g;
  g.seed = 3;
  const Scene<T> scene = generate_debris<T>(3000, g);
  BodyBuffer<T> original = scene.bodies;
  // Values with distinctive bits: -0, subnormal, inf in the inverse moments.
  {
    const BodyView<T> v = original.view();
    v.v.x[0] = T(-0.0);
    v.w.y[1] = std::numeric_limits<T>::denorm_min();
    v.inv_inertia.z[2] = T(0);
  }
  const BodyView<T> from = original.view();
  {
    PackedBuffer<PackedRigid<T>> packed(from.count);
    pack(from, packed_view(packed));
    BodyBuffer<T> back(from.count);
    unpack(packed_view(packed), back.view());
    EXPECT_TRUE(same_bodies(original, back));
    // Through a const view as well.
    PackedBuffer<PackedRigid<T>> again(from.count);
    pack(std::as_const(original).view(), packed_view(again));
    for (std::size_t i = 0; i < from.count; ++i) ASSERT_TRUE(same_record_bytes(packed[i], again[i])) << i;
    EXPECT_EQ(0, std::memcmp(packed.inv_mass.data(), from.inv_mass, from.count * sizeof(T)));
    EXPECT_EQ(packed.inv_mass, again.inv_mass);
  }
  {
    PackedBuffer<PackedSphere<T>> packed(from.count);
    pack(sphere_view(from), packed_view(packed));
    BodyBuffer<T> back = original;
    const SphereView<T> sv = sphere_view(back.view());
    for (std::size_t i = 0; i < from.count; ++i) sv.v.x[i] = sv.w.z[i] = sv.p.y[i] = T(7);
    unpack(packed_view(packed), sv);
    EXPECT_TRUE(same_bodies(original, back));
  }
  {
    PackedBuffer<PackedParticle<T>> packed(from.count);
    pack(particle_view(from), packed_view(packed));
    BodyBuffer<T> back = original;
    const ParticleView<T> pv = particle_view(back.view());
    for (std::size_t i = 0; i < from.count; ++i) pv.v.y[i] = T(7);
    unpack(packed_view(packed), pv);
    EXPECT_TRUE(same_bodies(original, back));
  }
  // unpack_velocities writes v and w of movable bodies only.
  {
    PackedBuffer<PackedRigid<T>> packed(from.count);
    pack(from, packed_view(packed));
    for (auto& r : packed.bodies) r.v[0] = T(42), r.w[2] = T(-42), r.p[1] = T(1e9);
    BodyBuffer<T> back = original;
    unpack_velocities(packed_view(packed), back.view());
    const BodyView<T> b = back.view();
    for (std::size_t i = 0; i < from.count; ++i) {
      const bool movable = from.inv_mass[i] != T(0);
      EXPECT_EQ(b.v.x[i], movable ? T(42) : from.v.x[i]) << i;
      EXPECT_EQ(b.w.z[i], movable ? T(-42) : from.w.z[i]) << i;
      EXPECT_EQ(b.p.y[i], from.p.y[i]) << i;  // never written
    }
  }
  // Mismatched counts are refused.
  PackedBuffer<PackedRigid<T>> small(from.count - 1);
  EXPECT_THROW(pack(from, packed_view(small)), std::invalid_argument);
  EXPECT_THROW(unpack(packed_view(small), original.view()), std::invalid_argument);
}

TEST(PackedLayout, RoundTripIsExactFloat) { expect_round_trip<float>(); }
TEST(PackedLayout, RoundTripIsExactDouble) { expect_round_trip<double>(); }

TEST(PackedLayout, RecordsAreAlignedAndSized) {
  PackedBuffer<PackedRigid<float>> r(3);
  PackedBuffer<PackedParticle<double>> p(5);
  PackedBuffer<PackedRigid<double>> rd(3);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(r.bodies.data()) % 64, 0u);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(rd.bodies.data()) % 128, 0u);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(p.bodies.data()) % 32, 0u);
  // One line per rigid float body, two per double: the inverse mass is beside the records.
  EXPECT_EQ(sizeof(PackedRigid<float>), 64u);
  EXPECT_EQ(sizeof(PackedRigid<double>), 128u);
  EXPECT_EQ(r.inv_mass.size(), 3u);
  EXPECT_EQ(sizeof(PackedSphere<float>), 64u);
  EXPECT_EQ(sizeof(PackedParticle<float>), 16u);
}

/// Solves `scene` with `model` on SoA (scalar path, the reference bits) and
/// then on every layout x path x ISA x thread count; every byte of v, w and J
/// must match.
template <class T>
void expect_layouts_agree(const Scene<T>& scene, Model model, const std::string& what) {
  SCOPED_TRACE(what + " " + type_name<T>() + " " + to_string(model));
  const ContactView<T> contacts = scene.contacts.view();
  Schedule schedule;
  {
    BodyBuffer<T> b = scene.bodies;
    schedule.build(contacts, b.view());
  }
  SolverOptions base_options = options_for(Path::scalar, 1);
  base_options.layout = BodyLayout::soa;
  BodyBuffer<T> base = scene.bodies;
  ImpulseBuffer<T> base_j(contacts.count);
  const SolveStats bs = Solver(base_options).solve(model, base.view(), contacts, base_j.view(), schedule);
  ASSERT_EQ(bs.layout, BodyLayout::soa);
  std::size_t acted = 0;
  for (std::size_t k = 0; k < contacts.count; ++k) acted += base_j.view().j.x[k] != 0;
  ASSERT_GT(acted, 0u);

  std::vector<std::pair<Path, Isa>> paths = {{Path::scalar, Isa::sse2}};
  for (const Isa isa : {Isa::sse2, Isa::avx2, Isa::avx512}) {
    if (isa_supported(isa)) paths.emplace_back(Path::simd, isa);
  }
  for (const auto& [path, isa] : paths) {
    for (const int threads : {1, 2}) {
      SolverOptions o = options_for(path, threads, 40);
      o.isa = isa;
      SCOPED_TRACE(std::string(to_string(path)) + " " + to_string(isa) + " threads " + std::to_string(threads));
      // SoA input that the solver packs.
      {
        o.layout = BodyLayout::packed;
        BodyBuffer<T> bodies = scene.bodies;
        ImpulseBuffer<T> j(contacts.count);
        const SolveStats s = Solver(o).solve(model, bodies.view(), contacts, j.view(), schedule);
        EXPECT_EQ(s.layout, BodyLayout::packed);
        EXPECT_TRUE(same_bodies(base, bodies));
        EXPECT_TRUE(same_impulses(base_j, j));
      }
      // The caller's records, converted back for the comparison.
      {
        BodyBuffer<T> bodies = scene.bodies;
        ImpulseBuffer<T> j(contacts.count);
        const Solver solver(o);
        SolveStats s;
        if (model == Model::rigid) {
          PackedBuffer<PackedRigid<T>> records(bodies.size());
          pack(bodies.view(), packed_view(records));
          s = solver.solve(packed_view(records), contacts, j.view(), schedule);
          unpack(packed_view(records), bodies.view());
        } else if (model == Model::sphere) {
          PackedBuffer<PackedSphere<T>> records(bodies.size());
          pack(sphere_view(bodies.view()), packed_view(records));
          s = solver.solve(packed_view(records), contacts, j.view(), schedule);
          unpack(packed_view(records), sphere_view(bodies.view()));
        } else {
          PackedBuffer<PackedParticle<T>> records(bodies.size());
          pack(particle_view(bodies.view()), packed_view(records));
          s = solver.solve(packed_view(records), contacts, j.view(), schedule);
          unpack(packed_view(records), particle_view(bodies.view()));
        }
        EXPECT_EQ(s.layout, BodyLayout::packed);
        EXPECT_EQ(s.model, model);
        EXPECT_TRUE(same_bodies(base, bodies));
        EXPECT_TRUE(same_impulses(base_j, j));
      }
    }
  }
}

template <class T>
void generated_scenes() {
  for (const Model model : {Model::particle, Model::sphere, Model::rigid}) {
    for (const bool friction : {false, true}) {
      GenerateOptions g;
      g.seed = 5;
      g.friction = friction;
      g.model = model;
      const std::string f = friction ? " friction" : "";
      expect_layouts_agree(generate_pairs<T>(1001, g), model, "pairs" + f);
      expect_layouts_agree(generate_debris<T>(2003, g), model, "debris" + f);
    }
  }
}

TEST(PackedLayout, SameBitsAsSoaGeneratedFloat) { generated_scenes<float>(); }
TEST(PackedLayout, SameBitsAsSoaGeneratedDouble) { generated_scenes<double>(); }

template <class T>
void shared_and_hard_scenes() {
  SceneOptions o;
  o.friction = true;
  expect_layouts_agree(shared_scene<T>(3001, 300, o), Model::rigid, "shared");
  expect_layouts_agree(collide::hard::mass_ratio_family<T>(301, Model::rigid, 21).scene(), Model::rigid, "mass ratio");
  expect_layouts_agree(collide::hard::immovable_family<T>(301, Model::rigid, 22).scene(), Model::rigid, "immovable");
  expect_layouts_agree(collide::hard::needle_family<T>(301, 23).scene(), Model::rigid, "needle");
  expect_layouts_agree(collide::hard::grazing_family<T>(301, Model::rigid, 24).scene(), Model::rigid, "grazing");
  expect_layouts_agree(collide::hard::subnormal_family<T>(301, Model::rigid, 25).scene(), Model::rigid, "subnormal");
}

TEST(PackedLayout, SameBitsAsSoaSharedAndHardFloat) { shared_and_hard_scenes<float>(); }
TEST(PackedLayout, SameBitsAsSoaSharedAndHardDouble) { shared_and_hard_scenes<double>(); }

/// The scene with its contacts permuted into the order of their schedule's
/// batches, as a caller that groups its contacts by level hands them over.
Scene<float> grouped_by_level(Scene<float> scene) {
  Schedule schedule;
  schedule.build(scene.contacts.view(), scene.bodies.view());
  Scene<float> out;
  out.bodies = scene.bodies;
  out.contacts.resize(scene.contacts.size());
  for (std::size_t i = 0; i < scene.contacts.size(); ++i) {
    out.contacts.set(i, scene.contacts.record(schedule.solve_order()[i]));
  }
  return out;
}

TEST(PackedLayout, AutomaticChoicePacksScatteredScenesOnly) {
  GenerateOptions g;
  g.seed = 9;
  auto layout_of = [](Scene<float> scene) {
    Schedule schedule;
    schedule.build(scene.contacts.view(), scene.bodies.view());
    ImpulseBuffer<float> j(scene.contacts.size());
    return Solver(options_for(Path::simd, 2))
        .solve(scene.bodies.view(), scene.contacts.view(), j.view(), schedule)
        .layout;
  };
  EXPECT_EQ(layout_of(generate_debris<float>(20000, g)), BodyLayout::packed);
  EXPECT_EQ(layout_of(generate_pairs<float>(20000, g)), BodyLayout::soa);
  // Too small to pay for packing.
  EXPECT_EQ(layout_of(generate_debris<float>(500, g)), BodyLayout::soa);
  // Debris handed over grouped by level: every batch is consecutive contacts,
  // but their bodies are still read at random, so the bodies are packed
  // (solved in place, such a scene runs several times slower than in input
  // order).
  Scene<float> grouped = grouped_by_level(generate_debris<float>(20000, g));
  {
    Schedule schedule;
    schedule.build(grouped.contacts.view(), grouped.bodies.view());
    ASSERT_GT(schedule.batch_count(), 3u);
    for (std::size_t k = 0; k < schedule.batch_count(); ++k) ASSERT_TRUE(schedule.batch_is_contiguous(k));
  }
  EXPECT_EQ(layout_of(grouped), BodyLayout::packed);
}

TEST(PackedLayout, ContactsGroupedByLevelSameBitsInEitherLayout) {
  GenerateOptions g;
  g.seed = 10;
  const Scene<float> scene = grouped_by_level(generate_debris<float>(20000, g));
  Scene<float> x = scene, y = scene;
  Schedule schedule;
  schedule.build(x.contacts.view(), x.bodies.view());
  ImpulseBuffer<float> jx(scene.contacts.size()), jy(scene.contacts.size());
  EXPECT_EQ(Solver(options_for(Path::simd, 2)).solve(x.bodies.view(), x.contacts.view(), jx.view(), schedule).layout,
            BodyLayout::packed);
  SolverOptions soa = options_for(Path::simd, 2);
  soa.layout = BodyLayout::soa;
  Solver(soa).solve(y.bodies.view(), y.contacts.view(), jy.view(), schedule);
  EXPECT_TRUE(same_bodies(x.bodies, y.bodies));
  EXPECT_TRUE(same_impulses(jx, jy));
}

TEST(PackedLayout, SolverReusesItsBufferAcrossSizes) {
  // Larger scenes after a smaller one and back: the buffers grow and are
  // reused; results stay those of SoA. 9000 and 30000 are both above the
  // size where the contacts are copied into schedule order, so the second
  // grows that copy's buffers (its index buffer once kept stale entries from
  // before the growth: out-of-range bodies, a crash in examples/debris).
  const Solver solver(options_for(Path::simd, 2));
  for (const std::size_t n : {std::size_t(3000), std::size_t(9000), std::size_t(30000), std::size_t(3000)}) {
    GenerateOptions g;
    g.seed = n;
    const Scene<float> scene = generate_debris<float>(n, g);
    Scene<float> x = scene, y = scene;
    Schedule schedule;
    schedule.build(x.contacts.view(), x.bodies.view());
    ImpulseBuffer<float> jx(n), jy(n);
    EXPECT_EQ(solver.solve(x.bodies.view(), x.contacts.view(), jx.view(), schedule).layout, BodyLayout::packed);
    SolverOptions soa = options_for(Path::simd, 2);
    soa.layout = BodyLayout::soa;
    Solver(soa).solve(y.bodies.view(), y.contacts.view(), jy.view(), schedule);
    EXPECT_TRUE(same_bodies(x.bodies, y.bodies));
    EXPECT_TRUE(same_impulses(jx, jy));
  }
}

TEST(PackedLayout, ParticleSolveNeedsNoContactPoint) {
  // validate() lets a particle view's contacts have no point (contacts.c
  // null). The packed path's prefetch of a scattered batch once offset
  // those null pointers: undefined behaviour, which the UBSan build of this
  // test reports. The results are those with the point present, on every
  // path and layout, and so are contact_slice()'s views of such contacts.
  for (const std::uint64_t seed : {1, 2}) {
    SceneOptions so;
    so.seed = seed;
    const Scene<float> scene = shared_scene<float>(3000, 500, so);
    Schedule schedule;
    {
      Scene<float> s = scene;
      schedule.build(s.contacts.view(), s.bodies.view());
    }
    ContactView<float> no_point = scene.contacts.view();
    no_point.c = {};
    Scene<float> probe = scene;
    ImpulseBuffer<float> probe_j(no_point.count);
    const Validation valid = validate(particle_view(probe.bodies.view()), no_point, probe_j.view());
    ASSERT_TRUE(valid) << valid.message;
    EXPECT_EQ(contact_slice(no_point, 7, 5).c.x, nullptr);
    for (const Path path : {Path::scalar, Path::simd}) {
      for (const BodyLayout layout : {BodyLayout::soa, BodyLayout::packed}) {
        SolverOptions o = options_for(path, 2, 64);
        o.layout = layout;
        const Solver solver(o);
        Scene<float> with = scene, without = scene;
        ImpulseBuffer<float> jw(scene.contacts.size()), jn(scene.contacts.size());
        solver.solve(particle_view(with.bodies.view()), with.contacts.view(), jw.view(), schedule);
        solver.solve(particle_view(without.bodies.view()), no_point, jn.view(), schedule);
        EXPECT_TRUE(same_bodies(with.bodies, without.bodies)) << to_string(path) << " " << to_string(layout);
        EXPECT_TRUE(same_impulses(jw, jn)) << to_string(path) << " " << to_string(layout);
        // The caller's packed records.
        Scene<float> rec = scene;
        PackedBuffer<PackedParticle<float>> records(rec.bodies.size());
        pack(particle_view(rec.bodies.view()), packed_view(records));
        ImpulseBuffer<float> jr(scene.contacts.size());
        solver.solve(packed_view(records), no_point, jr.view(), schedule);
        unpack_velocities(packed_view(records), particle_view(rec.bodies.view()));
        EXPECT_TRUE(same_bodies(with.bodies, rec.bodies)) << to_string(path);
        EXPECT_TRUE(same_impulses(jw, jr)) << to_string(path);
      }
    }
  }
}

}  // namespace
}  // namespace collide::test
