// test_drawn_scene.cpp - writing a drawn scene (collide/io/drawn_scene.hpp):
// the pairs, debris and pile scenes streamed to temporary files in CSV and
// in both npz precisions, read back with the io readers, hold exactly the
// scene the generators build in memory; the bytes do not depend on the
// threads; progress is reported per part; bad options are refused.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <oneapi/tbb/task_arena.h>

#include "collide/io/drawn_scene.hpp"
#include "collide/io/generate.hpp"
#include "collide/io/output_file.hpp"
#include "collide/io/scene_io.hpp"
#include "collide/io/scene_npz.hpp"

namespace fs = std::filesystem;
using collide::BodyRecord;
using collide::ContactRecord;
using collide::DrawnPairs;
using collide::DrawnScene;
using collide::DrawnSceneOptions;
using collide::GenerateOptions;
using collide::NpyType;
using collide::OutputFile;
using collide::SceneFormat;

namespace {

// Sizes that span several blocks of 8192 items (drawn_scene.cpp) and end
// inside one.
constexpr std::size_t kPairs = 9000;
constexpr std::size_t kDebris = 17001;
constexpr std::size_t kPileSide = 15;  // 3376 bodies, 9675 contacts

GenerateOptions options() {
  GenerateOptions o;
  o.seed = 12345;
  o.friction = true;
  return o;
}

DrawnPairs pairs_scene(std::size_t pairs, const GenerateOptions& o) {
  return {pairs, [o](std::uint64_t k, BodyRecord<double>& a, BodyRecord<double>& b, ContactRecord<double>& c) {
            collide::draw_pair(o, k, a, b, c);
          }};
}

DrawnScene debris_scene(std::size_t contacts, const GenerateOptions& o) {
  return {
      collide::debris_body_count(contacts), contacts,
      [contacts, o](std::uint64_t i, BodyRecord<double>& body) { collide::draw_debris_body(o, contacts, i, body); },
      [contacts, o](std::uint64_t k, ContactRecord<double>& c) { collide::draw_debris_contact(o, contacts, k, c); }};
}

DrawnScene pile_scene(std::size_t side, const GenerateOptions& o) {
  return {collide::pile_body_count(side), collide::pile_contact_count(side),
          [side, o](std::uint64_t i, BodyRecord<double>& body) { collide::draw_pile_body(o, side, i, body); },
          [side, o](std::uint64_t k, ContactRecord<double>& c) { collide::draw_pile_contact(o, side, k, c); }};
}

class DrawnSceneTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() / (std::string("collide_drawn_scene_") + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  /// Writes `scene` as dir/<name>/bodies.<ext> and contacts.<ext>; returns
  /// the two paths.
  template <class Drawn>
  std::pair<std::string, std::string> write(const std::string& name, const Drawn& scene,
                                            const DrawnSceneOptions& how) const {
    fs::create_directories(dir_ / name);
    const std::string ext = how.format == SceneFormat::npz ? ".npz" : ".csv";
    const std::string bodies_path = (dir_ / name / ("bodies" + ext)).string();
    const std::string contacts_path = (dir_ / name / ("contacts" + ext)).string();
    OutputFile bodies(bodies_path);
    OutputFile contacts(contacts_path);
    collide::write_drawn_scene(scene, how, bodies, contacts);
    bodies.commit();
    contacts.commit();
    return {bodies_path, contacts_path};
  }

  fs::path dir_;
};

template <class T>
void expect_same_array(const T* got, const T* want, std::size_t n, const char* what) {
  for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(got[i], want[i]) << what << " of row " << i;
}

/// The files read back with load_bodies / load_contacts in T hold exactly
/// `want`: the same stored values after the same conversions.
template <class T>
void expect_files_hold(const std::pair<std::string, std::string>& files, SceneFormat format,
                       const collide::Scene<T>& want) {
  const auto loaded_bodies = collide::load_bodies<T>(files.first, format);
  const collide::BodyBuffer<T> bodies = collide::to_body_buffer(loaded_bodies.columns());
  const auto got = bodies.view();
  const auto exp = want.bodies.view();
  ASSERT_EQ(got.count, exp.count);
  const std::size_t n = got.count;
  expect_same_array(got.inv_mass, exp.inv_mass, n, "inv_mass");
  expect_same_array(got.inv_inertia.x, exp.inv_inertia.x, n, "inv_inertia.x");
  expect_same_array(got.inv_inertia.y, exp.inv_inertia.y, n, "inv_inertia.y");
  expect_same_array(got.inv_inertia.z, exp.inv_inertia.z, n, "inv_inertia.z");
  expect_same_array(got.q.w, exp.q.w, n, "q.w");
  expect_same_array(got.q.x, exp.q.x, n, "q.x");
  expect_same_array(got.q.y, exp.q.y, n, "q.y");
  expect_same_array(got.q.z, exp.q.z, n, "q.z");
  expect_same_array(got.p.x, exp.p.x, n, "p.x");
  expect_same_array(got.p.y, exp.p.y, n, "p.y");
  expect_same_array(got.p.z, exp.p.z, n, "p.z");
  expect_same_array(got.v.x, exp.v.x, n, "v.x");
  expect_same_array(got.v.y, exp.v.y, n, "v.y");
  expect_same_array(got.v.z, exp.v.z, n, "v.z");
  expect_same_array(got.w.x, exp.w.x, n, "w.x");
  expect_same_array(got.w.y, exp.w.y, n, "w.y");
  expect_same_array(got.w.z, exp.w.z, n, "w.z");

  const auto loaded_contacts = collide::load_contacts<T>(files.second, format, n);
  const collide::ContactView<T>& c = loaded_contacts.view();
  const collide::ContactView<T> e = want.contacts.view();
  ASSERT_EQ(c.count, e.count);
  expect_same_array(c.a, e.a, c.count, "a");
  expect_same_array(c.b, e.b, c.count, "b");
  expect_same_array(c.c.x, e.c.x, c.count, "cx");
  expect_same_array(c.c.y, e.c.y, c.count, "cy");
  expect_same_array(c.c.z, e.c.z, c.count, "cz");
  expect_same_array(c.n.x, e.n.x, c.count, "nx");
  expect_same_array(c.n.y, e.n.y, c.count, "ny");
  expect_same_array(c.n.z, e.n.z, c.count, "nz");
  for (std::size_t k = 0; k < c.count; ++k) {
    ASSERT_EQ(c.e ? c.e[k] : c.uniform_e, e.e ? e.e[k] : e.uniform_e) << "e of row " << k;
    ASSERT_EQ(c.mu ? c.mu[k] : T(0), e.mu ? e.mu[k] : T(0)) << "mu of row " << k;
  }
}

DrawnSceneOptions csv() { return {}; }
DrawnSceneOptions npz(NpyType precision) {
  DrawnSceneOptions how;
  how.format = SceneFormat::npz;
  how.precision = precision;
  return how;
}

TEST_F(DrawnSceneTest, PairsInEveryFormatAreGeneratePairs) {
  const DrawnPairs scene = pairs_scene(kPairs, options());
  const auto want = collide::generate_pairs<double>(kPairs, options());
  expect_files_hold(write("csv", scene, csv()), SceneFormat::csv, want);
  expect_files_hold(write("f8", scene, npz(NpyType::f8)), SceneFormat::npz, want);
  expect_files_hold(write("f4", scene, npz(NpyType::f4)), SceneFormat::npz,
                    collide::generate_pairs<float>(kPairs, options()));
}

TEST_F(DrawnSceneTest, DebrisInEveryFormatIsGenerateDebris) {
  const DrawnScene scene = debris_scene(kDebris, options());
  const auto want = collide::generate_debris<double>(kDebris, options());
  expect_files_hold(write("csv", scene, csv()), SceneFormat::csv, want);
  expect_files_hold(write("f8", scene, npz(NpyType::f8)), SceneFormat::npz, want);
  expect_files_hold(write("f4", scene, npz(NpyType::f4)), SceneFormat::npz,
                    collide::generate_debris<float>(kDebris, options()));
}

TEST_F(DrawnSceneTest, PileInEveryFormatIsGeneratePile) {
  GenerateOptions shuffled = options();
  shuffled.shuffle = true;
  for (const GenerateOptions& o : {options(), shuffled}) {
    const DrawnScene scene = pile_scene(kPileSide, o);
    const auto want = collide::generate_pile<double>(kPileSide, o);
    const std::string tag = o.shuffle ? "shuffled_" : "";
    expect_files_hold(write(tag + "csv", scene, csv()), SceneFormat::csv, want);
    expect_files_hold(write(tag + "f8", scene, npz(NpyType::f8)), SceneFormat::npz, want);
    expect_files_hold(write(tag + "f4", scene, npz(NpyType::f4)), SceneFormat::npz,
                      collide::generate_pile<float>(kPileSide, o));
  }
}

TEST_F(DrawnSceneTest, EmptyScenesAreHeadersOnly) {
  const auto pairs = write("pairs", pairs_scene(0, options()), csv());
  EXPECT_EQ(collide::read_file(pairs.first), collide::bodies_header());
  EXPECT_EQ(collide::read_file(pairs.second), collide::contacts_header());
  const auto debris = write("debris", debris_scene(0, options()), npz(NpyType::f8));
  expect_files_hold(debris, SceneFormat::npz, collide::generate_debris<double>(0, options()));
}

TEST_F(DrawnSceneTest, BytesDoNotDependOnTheThreads) {
  const DrawnPairs pairs = pairs_scene(kPairs, options());
  const DrawnScene debris = debris_scene(kDebris, options());
  for (const DrawnSceneOptions& how : {csv(), npz(NpyType::f4)}) {
    const auto many_pairs = write("many_pairs", pairs, how);
    const auto many_debris = write("many_debris", debris, how);
    std::pair<std::string, std::string> one_pairs, one_debris;
    oneapi::tbb::task_arena(1).execute([&] {
      one_pairs = write("one_pairs", pairs, how);
      one_debris = write("one_debris", debris, how);
    });
    EXPECT_EQ(collide::read_file(one_pairs.first), collide::read_file(many_pairs.first));
    EXPECT_EQ(collide::read_file(one_pairs.second), collide::read_file(many_pairs.second));
    EXPECT_EQ(collide::read_file(one_debris.first), collide::read_file(many_debris.first));
    EXPECT_EQ(collide::read_file(one_debris.second), collide::read_file(many_debris.second));
  }
}

TEST_F(DrawnSceneTest, ProgressCountsEachPartUpToItsTotal) {
  struct Call {
    std::string part;
    std::size_t done, total;
  };
  std::vector<Call> calls;
  DrawnSceneOptions how;
  how.progress = [&calls](std::string_view part, std::size_t done, std::size_t total) {
    calls.push_back({std::string(part), done, total});
  };
  write("debris", debris_scene(kDebris, options()), how);
  const std::size_t bodies = collide::debris_body_count(kDebris);
  // 8501 bodies: blocks end at 8192 and 8501; 17001 contacts: 8192, 16384, 17001.
  const std::vector<std::pair<std::string, std::size_t>> want = {
      {"bodies", 8192}, {"bodies", bodies}, {"contacts", 8192}, {"contacts", 16384}, {"contacts", kDebris}};
  ASSERT_EQ(calls.size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i) {
    EXPECT_EQ(calls[i].part, want[i].first) << i;
    EXPECT_EQ(calls[i].done, want[i].second) << i;
    EXPECT_EQ(calls[i].total, want[i].first == "bodies" ? bodies : kDebris) << i;
  }
  calls.clear();
  write("pairs", pairs_scene(kPairs, options()), how);
  ASSERT_EQ(calls.size(), 2U);
  EXPECT_EQ(calls[0].part, "pairs");
  EXPECT_EQ(calls[0].done, 8192U);
  EXPECT_EQ(calls[1].done, kPairs);
  EXPECT_EQ(calls[1].total, kPairs);
}

TEST_F(DrawnSceneTest, RefusesAPrecisionItCannotWrite) {
  DrawnSceneOptions float_csv;
  float_csv.precision = NpyType::f4;
  EXPECT_THROW(write("a", pairs_scene(3, options()), float_csv), std::invalid_argument);
  EXPECT_THROW(write("b", debris_scene(3, options()), npz(NpyType::u4)), std::invalid_argument);
  // Nothing was committed.
  EXPECT_FALSE(fs::exists(dir_ / "a" / "bodies.csv"));
  EXPECT_FALSE(fs::exists(dir_ / "b" / "bodies.npz"));
}

}  // namespace
