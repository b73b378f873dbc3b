// test_scene_routes.cpp - one scene, one answer (docs/collision-law.md,
// "Scene values"): the same scene through every route that reaches the
// solver in process (the CSV reader, the .npz reader from '<f8' and '<f4'
// files, mixed files, a C++ caller's double columns through narrow_bodies
// and SolveBodies, the generators in memory), in float and double, fast and
// accurate, gives the same bytes of v, w and J; a value beyond float and a
// subnormal the rules refuse are refused by every route with one message,
// at one row and column.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <optional>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "collide/io/drawn_scene.hpp"
#include "collide/io/generate.hpp"
#include "collide/io/output_file.hpp"
#include "collide/io/scene.hpp"
#include "collide/io/scene_io.hpp"
#include "collide/io/scene_npz.hpp"
#include "collide/io/scene_values.hpp"
#include "collide/model.hpp"
#include "collide/schedule.hpp"
#include "collide/solve.hpp"
#include "support/scene_value_text.hpp"

namespace fs = std::filesystem;
using collide::Accuracy;
using collide::BodyColumns;
using collide::BodyRules;
using collide::BodyTable;
using collide::BodyView;
using collide::ContactBuffer;
using collide::ContactView;
using collide::OutputFile;
using collide::SceneError;
using collide::SceneFormat;
using collide::test::ValueText;

namespace {

// ---------------------------------------------------------------------------
// A solve and its outputs
// ---------------------------------------------------------------------------

/// v and w of every body and J of every contact after a solve.
template <class T>
struct Outputs {
  std::array<std::vector<T>, 6> vw;
  std::array<std::vector<T>, 3> j;
};

/// Solves as `collide solve` does (the model that fits, any threads) and
/// keeps the outputs.
template <class T>
Outputs<T> solve(const BodyView<T>& bodies, const ContactView<T>& contacts, Accuracy accuracy) {
  collide::SolverOptions options;
  options.accuracy = accuracy;
  collide::Schedule schedule;
  schedule.build(contacts, bodies);
  collide::ImpulseBuffer<T> j(contacts.count);
  const collide::Model model = collide::choose_model(bodies, contacts);
  collide::Solver(options).solve(model, bodies, contacts, j.view(), schedule);
  Outputs<T> out;
  const T* const vw[6] = {bodies.v.x, bodies.v.y, bodies.v.z, bodies.w.x, bodies.w.y, bodies.w.z};
  for (std::size_t k = 0; k < 6; ++k) out.vw[k].assign(vw[k], vw[k] + bodies.count);
  const auto jv = j.view();
  const T* const jj[3] = {jv.j.x, jv.j.y, jv.j.z};
  for (std::size_t k = 0; k < 3; ++k) out.j[k].assign(jj[k], jj[k] + contacts.count);
  return out;
}

/// Whether two solves gave the same bytes; the first difference otherwise.
template <class T>
::testing::AssertionResult same_bytes(const Outputs<T>& x, const Outputs<T>& y) {
  static const char* const names[9] = {"vx", "vy", "vz", "wx", "wy", "wz", "jx", "jy", "jz"};
  for (std::size_t k = 0; k < 9; ++k) {
    const std::vector<T>& a = k < 6 ? x.vw[k] : x.j[k - 6];
    const std::vector<T>& b = k < 6 ? y.vw[k] : y.j[k - 6];
    if (a.size() != b.size()) return ::testing::AssertionFailure() << names[k] << ": sizes differ";
    for (std::size_t i = 0; i < a.size(); ++i) {
      if (std::memcmp(&a[i], &b[i], sizeof(T)) != 0) {
        return ::testing::AssertionFailure() << names[k] << "[" << i << "] = " << a[i] << " against " << b[i];
      }
    }
  }
  return ::testing::AssertionSuccess();
}

// ---------------------------------------------------------------------------
// The routes
// ---------------------------------------------------------------------------

/// The CSV reader (collide.read_scene's and `collide solve`'s for CSV):
/// a table, then the buffer the kernels take.
template <class T>
Outputs<T> csv_route(const std::string& bodies, const std::string& contacts, Accuracy accuracy) {
  const BodyTable<T> table = collide::read_bodies<T>(bodies);
  const ContactBuffer<T> c = collide::read_contacts<T>(contacts, table.size());
  collide::BodyBuffer<T> b = collide::to_body_buffer(table);
  return solve(b.view(), c.view(), accuracy);
}

/// load_bodies / load_contacts and SolveBodies (`collide solve`'s and
/// collide.load's): CSV or .npz by each name.
template <class T>
Outputs<T> load_route(const std::string& bodies, const std::string& contacts, Accuracy accuracy) {
  const auto loaded = collide::load_bodies<T>(bodies, collide::scene_format_of(bodies), BodyRules::by_caller);
  collide::SolveBodies<T> b(loaded);
  const auto c = collide::load_contacts<T>(contacts, collide::scene_format_of(contacts), loaded.size());
  return solve(b.view(), c.view(), accuracy);
}

/// A C++ caller holding the scene as doubles: narrow_bodies, then
/// SolveBodies from the columns; the contacts' records rounded by
/// detail::narrow into a buffer.
template <class T>
Outputs<T> columns_route(const std::string& bodies_csv, const std::string& contacts_csv, Accuracy accuracy) {
  const BodyTable<double> wide = collide::read_bodies<double>(bodies_csv);
  BodyTable<T> table;
  const std::optional<collide::RowDefect> defect = collide::narrow_bodies(collide::columns_of(wide), table);
  EXPECT_FALSE(defect.has_value()) << defect->defect.reason;
  collide::SolveBodies<T> b(collide::columns_of(table));
  const ContactBuffer<double> wide_contacts = collide::read_contacts<double>(contacts_csv, wide.size());
  ContactBuffer<T> c(wide_contacts.size());
  for (std::size_t k = 0; k < wide_contacts.size(); ++k) {
    c.set(k, collide::detail::narrow<T>(wide_contacts.record(k)));
  }
  return solve(b.view(), c.view(), accuracy);
}

/// A scene's files in every format, as `collide convert` writes them: dir/
/// bodies.csv, contacts.csv (the text given), f8/bodies.npz ('<f8': the
/// doubles the text reads as), f4/bodies.npz ('<f4': the CSV read in float).
struct SceneFiles {
  std::string csv_bodies, csv_contacts, f8_bodies, f8_contacts, f4_bodies, f4_contacts;
};

void write_text(const fs::path& path, const std::string& text) { std::ofstream(path, std::ios::binary) << text; }

/// As `collide convert --in <csv> --out <npz> --precision <T>`.
template <class T>
void convert_to_npz(const std::string& bodies_csv, const std::string& contacts_csv, const std::string& bodies_npz,
                    const std::string& contacts_npz) {
  OutputFile ob(bodies_npz), oc(contacts_npz);
  collide::write_body_table(ob, SceneFormat::npz, collide::load_bodies<T>(bodies_csv, SceneFormat::csv).columns());
  collide::write_contacts(oc, SceneFormat::npz,
                          collide::load_contacts<T>(contacts_csv, SceneFormat::csv, collide::kUnknownBodyCount).view());
  ob.commit();
  oc.commit();
}

SceneFiles scene_files(const fs::path& dir) {
  SceneFiles f;
  f.csv_bodies = (dir / "bodies.csv").string();
  f.csv_contacts = (dir / "contacts.csv").string();
  fs::create_directories(dir / "f8");
  fs::create_directories(dir / "f4");
  f.f8_bodies = (dir / "f8" / "bodies.npz").string();
  f.f8_contacts = (dir / "f8" / "contacts.npz").string();
  f.f4_bodies = (dir / "f4" / "bodies.npz").string();
  f.f4_contacts = (dir / "f4" / "contacts.npz").string();
  convert_to_npz<double>(f.csv_bodies, f.csv_contacts, f.f8_bodies, f.f8_contacts);
  convert_to_npz<float>(f.csv_bodies, f.csv_contacts, f.f4_bodies, f.f4_contacts);
  return f;
}

/// Every file route of `files` in T and `accuracy` gives the bytes of the
/// CSV reader's solve; `more` adds routes of the caller's (the generators).
template <class T>
void expect_every_route_agrees(const SceneFiles& f, Accuracy accuracy,
                               const std::vector<std::pair<std::string, std::function<Outputs<T>()>>>& more = {}) {
  const Outputs<T> want = csv_route<T>(f.csv_bodies, f.csv_contacts, accuracy);
  std::vector<std::pair<std::string, std::function<Outputs<T>()>>> routes = {
      {"load csv", [&] { return load_route<T>(f.csv_bodies, f.csv_contacts, accuracy); }},
      {"npz f8", [&] { return load_route<T>(f.f8_bodies, f.f8_contacts, accuracy); }},
      {"csv bodies, npz f8 contacts", [&] { return load_route<T>(f.csv_bodies, f.f8_contacts, accuracy); }},
      {"npz f8 bodies, csv contacts", [&] { return load_route<T>(f.f8_bodies, f.csv_contacts, accuracy); }},
      {"double columns", [&] { return columns_route<T>(f.csv_bodies, f.csv_contacts, accuracy); }},
  };
  if constexpr (std::is_same_v<T, float>) {
    // A float file holds the float scene; in double it is another scene.
    routes.emplace_back("npz f4", [&] { return load_route<T>(f.f4_bodies, f.f4_contacts, accuracy); });
    routes.emplace_back("npz f4 bodies, csv contacts",
                        [&] { return load_route<T>(f.f4_bodies, f.csv_contacts, accuracy); });
  }
  routes.insert(routes.end(), more.begin(), more.end());
  for (const auto& [name, route] : routes) {
    EXPECT_TRUE(same_bytes(route(), want))
        << name << ", " << collide::precision_name<T>() << ", " << (accuracy == Accuracy::fast ? "fast" : "accurate");
  }
}

class SceneRoutes : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() / (std::string("collide_scene_routes_") + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(dir_);
  }
  fs::path dir_;
};

// ---------------------------------------------------------------------------
// The two bodies the roundings part on
// ---------------------------------------------------------------------------

TEST_F(SceneRoutes, TheTwoBodiesGiveOneAnswer) {
  fs::copy(fs::path(COLLIDE_DATA_DIR) / "scene-values" / "two-bodies", dir_, fs::copy_options::recursive);
  const SceneFiles f = scene_files(dir_);
  // wz of body 0 is written 8.856279850006104: its double is halfway between
  // two floats (docs/collision-law.md, "Scene values"), and the float a
  // solve sees is the even one below, not the one nearest the text.
  EXPECT_TRUE(collide::test::roundings_part("8.856279850006104"));
  EXPECT_EQ(collide::read_bodies<float>(f.csv_bodies).column[BodyTable<float>::wz][0],
            static_cast<float>(8.856279850006104));
  for (const Accuracy accuracy : {Accuracy::fast, Accuracy::accurate}) {
    expect_every_route_agrees<float>(f, accuracy);
    expect_every_route_agrees<double>(f, accuracy);
    // The answer, in the shortest text `collide solve` writes.
    const Outputs<float> out = csv_route<float>(f.csv_bodies, f.csv_contacts, accuracy);
    EXPECT_EQ(collide::test::shortest_text(out.vw[5][0]), "6.996387");
  }
}

// ---------------------------------------------------------------------------
// Drawn scenes of text where the roundings part
// ---------------------------------------------------------------------------

/// Draws text near the finite float f: every kind of ValueText (midpoint
/// kinds only below the largest float).
std::string draw_text(std::mt19937_64& rng, float f) {
  auto kind = static_cast<ValueText>(rng() % static_cast<std::uint64_t>(ValueText::kCount));
  if (std::fabs(f) == std::numeric_limits<float>::max()) kind = ValueText::float_long;
  return collide::test::value_text(f, kind);
}

/// Which extreme floats a field may draw besides its range.
enum class Extremes { none, subnormal, subnormal_and_largest };

/// A float drawn for a field: mostly uniform in [lo, hi), sometimes (as
/// `extremes` allows) subnormal or one of the largest floats, with a random
/// sign when `signed_value`.
float draw_float(std::mt19937_64& rng, double lo, double hi, Extremes extremes, bool signed_value) {
  std::uniform_real_distribution<double> u(lo, hi);
  float f = static_cast<float>(u(rng));
  const std::uint64_t pick = rng() % 100;
  if (extremes != Extremes::none && pick < 8) {
    // A subnormal float: any of the 2^23 - 1.
    f = std::bit_cast<float>(static_cast<std::uint32_t>(1 + rng() % 0x7FFFFE));
  } else if (extremes == Extremes::subnormal_and_largest && pick < 40) {
    // One of the four largest floats.
    f = std::bit_cast<float>(static_cast<std::uint32_t>(0x7F7FFFFF - rng() % 4));
  }
  if (signed_value && (rng() & 1)) f = -f;
  return f;
}

/// The text of a scene of `bodies` bodies and `contacts` contacts, every
/// value written as draw_text writes it: halfway cases, text longer than its
/// float's, subnormals, values near float's largest. The contacts join
/// random pairs of the bodies (sharing them), except the last kLoners, which
/// join the last 2 kLoners bodies in pairs of their own: only those hold
/// the largest floats, whose solves overflow in float, so that the NaN they
/// give stays with them. All of it obeys the rules in both precisions.
/// Returns the number of fields whose two roundings part.
constexpr std::size_t kLoners = 20;
std::size_t draw_scene(std::uint64_t seed, std::size_t bodies, std::size_t contacts, std::string& bodies_csv,
                       std::string& contacts_csv) {
  std::mt19937_64 rng(seed);
  std::size_t parted = 0;
  auto put = [&](std::string& out, const std::string& text, bool last) {
    parted += collide::test::roundings_part(text) ? 1 : 0;
    out += text;
    out += last ? '\n' : ',';
  };
  const std::size_t shared = bodies - 2 * kLoners;
  bodies_csv = std::string(collide::bodies_header());
  std::normal_distribution<double> gauss;
  for (std::size_t i = 0; i < bodies; ++i) {
    const Extremes extremes = i < shared ? Extremes::subnormal : Extremes::subnormal_and_largest;
    // m and the moments: positive and normal (a subnormal one is refused:
    // SubnormalsTheRulesRefuse...), sometimes half the largest float,
    // sometimes inf.
    for (int k = 0; k < 4; ++k) {
      const std::uint64_t pick = rng() % 50;
      if (pick == 0) {
        bodies_csv += "inf,";
      } else {
        const float x =
            pick == 1 ? std::numeric_limits<float>::max() / 2 : draw_float(rng, 0.25, 40.0, Extremes::none, false);
        put(bodies_csv, draw_text(rng, x), false);
      }
    }
    // q: a random direction (its length need not be 1), components near
    // their floats, now and then a subnormal one.
    for (int k = 0; k < 4; ++k) {
      float x = static_cast<float>(gauss(rng));
      if (rng() % 20 == 0) x = std::bit_cast<float>(static_cast<std::uint32_t>(1 + rng() % 0x7FFFFE));
      put(bodies_csv, draw_text(rng, x), false);
    }
    // p, v, w.
    for (int k = 0; k < 9; ++k) {
      const double scale = k < 3 ? 100.0 : 10.0;
      put(bodies_csv, draw_text(rng, draw_float(rng, -scale, scale, extremes, true)), k == 8);
    }
  }
  contacts_csv = std::string(collide::contacts_header());
  for (std::size_t k = 0; k < contacts; ++k) {
    const bool loner = k + kLoners >= contacts;
    std::size_t a = 0, b = 0;
    if (loner) {
      a = shared + 2 * (k + kLoners - contacts);
      b = a + 1;
    } else {
      a = rng() % shared;
      b = (a + 1 + rng() % (shared - 1)) % shared;
    }
    contacts_csv += std::to_string(a) + "," + std::to_string(b) + ",";
    const Extremes extremes = loner ? Extremes::subnormal_and_largest : Extremes::subnormal;
    for (int c = 0; c < 3; ++c)
      put(contacts_csv, draw_text(rng, draw_float(rng, -100.0, 100.0, extremes, true)), false);
    // A unit normal, each component near its float.
    double n[3] = {gauss(rng), gauss(rng), gauss(rng)};
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (double& x : n) put(contacts_csv, draw_text(rng, static_cast<float>(x / len)), false);
    put(contacts_csv, draw_text(rng, draw_float(rng, 0.0, 0.999, Extremes::none, false)), false);  // e
    put(contacts_csv, draw_text(rng, draw_float(rng, 0.0, 1.0, Extremes::none, false)), true);     // mu
  }
  return parted;
}

TEST_F(SceneRoutes, DrawnValuesWhereTheRoundingsPartGiveOneAnswer) {
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    const fs::path dir = dir_ / ("seed" + std::to_string(seed));
    fs::create_directories(dir);
    std::string bodies, contacts;
    const std::size_t parted = draw_scene(seed, 300, 900, bodies, contacts);
    // The scene is made of the cases it is about: about a fifth of its fields.
    EXPECT_GT(parted, 1000u) << "seed " << seed;
    write_text(dir / "bodies.csv", bodies);
    write_text(dir / "contacts.csv", contacts);
    const SceneFiles f = scene_files(dir);
    for (const Accuracy accuracy : {Accuracy::fast, Accuracy::accurate}) {
      expect_every_route_agrees<float>(f, accuracy);
      expect_every_route_agrees<double>(f, accuracy);
    }
  }
}

TEST_F(SceneRoutes, ACsvFieldIsTheFloatOfItsDouble) {
  std::mt19937_64 rng(7);
  std::string text = std::string(collide::bodies_header());
  std::vector<float> want;
  for (int i = 0; i < 2000; ++i) {
    text += "1,1,1,1,1,0,0,0,0,0,0,";
    const float f = draw_float(rng, -10.0, 10.0, Extremes::subnormal, true);
    const std::string t = collide::test::value_text(f, static_cast<ValueText>(i % 5));
    want.push_back(static_cast<float>(std::strtod(t.c_str(), nullptr)));
    text += t + ",0,0,0,0,0\n";
  }
  // Both of the reader's paths: plain text, and blanks that send each row to
  // the careful one.
  std::string blanks;
  for (const char c : text) blanks += c == ',' ? std::string(", ") : std::string(1, c);
  for (const std::string& t : {text, blanks}) {
    const BodyTable<float> table = collide::parse_bodies<float>(t, "b.csv");
    for (std::size_t i = 0; i < want.size(); ++i) {
      ASSERT_EQ(std::bit_cast<std::uint32_t>(table.column[BodyTable<float>::vx][i]),
                std::bit_cast<std::uint32_t>(want[i]))
          << "row " << i;
    }
  }
}

TEST_F(SceneRoutes, EveryFloatWrittenReadsBack) {
  // The one float whose shortest text reads, through its double, as the
  // float above (the double is within half its spacing of the midpoint
  // between them, and ties go to the even one): the writers give it a digit
  // more.
  const float odd = std::bit_cast<float>(std::uint32_t{0x15AE43FD});
  EXPECT_EQ(collide::test::shortest_text(odd), "7.038531e-26");
  EXPECT_EQ(std::bit_cast<std::uint32_t>(static_cast<float>(7.038531e-26)), 0x15AE43FEu);
  std::string text = std::string(collide::bodies_header());
  std::vector<float> want;
  std::mt19937_64 rng(11);
  for (int i = 0; i < 200000; ++i) {
    float f = std::bit_cast<float>(static_cast<std::uint32_t>(rng()));
    if (i < 6)
      f = std::bit_cast<float>(std::uint32_t{0x15AE43FC} + static_cast<std::uint32_t>(i % 3)) * (i < 3 ? 1 : -1);
    if (!std::isfinite(f)) continue;
    want.push_back(f);
    text += "1,1,1,1,1,0,0,0,0,0,0,";
    collide::append_number(text, f);
    text += ",0,0,0,0,0\n";
  }
  EXPECT_NE(text.find("\n1,1,1,1,1,0,0,0,0,0,0,7.0385307e-26,"), std::string::npos);
  EXPECT_NE(text.find("\n1,1,1,1,1,0,0,0,0,0,0,-7.0385307e-26,"), std::string::npos);
  const BodyTable<float> table = collide::parse_bodies<float>(text, "b.csv");
  ASSERT_EQ(table.size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i) {
    ASSERT_EQ(std::bit_cast<std::uint32_t>(table.column[BodyTable<float>::vx][i]),
              std::bit_cast<std::uint32_t>(want[i]))
        << "row " << i;
  }
}

// ---------------------------------------------------------------------------
// The generated scenes
// ---------------------------------------------------------------------------

collide::GenerateOptions generated(bool friction) {
  collide::GenerateOptions o;
  o.seed = 2;
  o.friction = friction;
  return o;
}

/// Writes a drawn scene's CSV (the shortest text of the doubles drawn, as
/// `collide gen` writes it) into `dir` and checks every route, the
/// generator's own scene in memory among them.
template <class Drawn, class Generate>
void expect_generated_scene_agrees(const fs::path& dir, const Drawn& drawn, const Generate& generate) {
  fs::create_directories(dir);
  {
    OutputFile b((dir / "bodies.csv").string()), c((dir / "contacts.csv").string());
    collide::write_drawn_scene(drawn, collide::DrawnSceneOptions{}, b, c);
    b.commit();
    c.commit();
  }
  const SceneFiles f = scene_files(dir);
  for (const Accuracy accuracy : {Accuracy::fast, Accuracy::accurate}) {
    auto in_memory = [&](auto tag) {
      using T = decltype(tag);
      return std::vector<std::pair<std::string, std::function<Outputs<T>()>>>{
          {"generated in memory", [&] {
             collide::Scene<T> s = generate(tag);
             return solve(s.bodies.view(), s.contacts.view(), accuracy);
           }}};
    };
    expect_every_route_agrees<float>(f, accuracy, in_memory(float{}));
    expect_every_route_agrees<double>(f, accuracy, in_memory(double{}));
  }
}

TEST_F(SceneRoutes, GeneratedPairsGiveOneAnswer) {
  constexpr std::size_t kPairs = 20000;
  const collide::GenerateOptions o = generated(true);
  const collide::DrawnPairs drawn{kPairs,
                                  [o](std::uint64_t k, collide::BodyRecord<double>& a, collide::BodyRecord<double>& b,
                                      collide::ContactRecord<double>& c) { collide::draw_pair(o, k, a, b, c); }};
  expect_generated_scene_agrees(dir_, drawn,
                                [&](auto tag) { return collide::generate_pairs<decltype(tag)>(kPairs, o); });
}

TEST_F(SceneRoutes, GeneratedDebrisGivesOneAnswer) {
  constexpr std::size_t kContacts = 30000;
  const collide::GenerateOptions o = generated(true);
  const collide::DrawnScene drawn{
      collide::debris_body_count(kContacts), kContacts,
      [o](std::uint64_t i, collide::BodyRecord<double>& body) { collide::draw_debris_body(o, kContacts, i, body); },
      [o](std::uint64_t k, collide::ContactRecord<double>& c) { collide::draw_debris_contact(o, kContacts, k, c); }};
  expect_generated_scene_agrees(dir_, drawn,
                                [&](auto tag) { return collide::generate_debris<decltype(tag)>(kContacts, o); });
}

TEST_F(SceneRoutes, GeneratedPileGivesOneAnswer) {
  constexpr std::size_t kSide = 14;
  const collide::GenerateOptions o = generated(false);
  const collide::DrawnScene drawn{
      collide::pile_body_count(kSide), collide::pile_contact_count(kSide),
      [o](std::uint64_t i, collide::BodyRecord<double>& body) { collide::draw_pile_body(o, kSide, i, body); },
      [o](std::uint64_t k, collide::ContactRecord<double>& c) { collide::draw_pile_contact(o, kSide, k, c); }};
  expect_generated_scene_agrees(dir_, drawn, [&](auto tag) { return collide::generate_pile<decltype(tag)>(kSide, o); });
}

// ---------------------------------------------------------------------------
// What every route refuses, with one message
// ---------------------------------------------------------------------------

/// A defect as the routes report it: row, column, reason.
struct Refusal {
  std::size_t row;
  std::string column;
  std::string reason;
};

bool operator==(const Refusal& x, const Refusal& y) {
  return x.row == y.row && x.column == y.column && x.reason == y.reason;
}

std::ostream& operator<<(std::ostream& os, const Refusal& r) {
  return os << "row " << r.row << ", column '" << r.column << "': " << r.reason;
}

template <class F>
Refusal scene_refusal(const F& f) {
  try {
    f();
  } catch (const SceneError& e) {
    return {e.row(), e.column(), e.reason()};
  }
  ADD_FAILURE() << "no SceneError";
  return {};
}

constexpr const char* kGoodBody = "2,1,1,1,1,0,0,0,0,0,0,0.5,-3,0,0,0,1";

/// A bodies file of `rows` good bodies with the fields of `changes` (row,
/// column index, text) replaced.
std::string bodies_text(std::size_t rows,
                        const std::vector<std::tuple<std::size_t, std::size_t, std::string>>& changes) {
  std::string text(collide::bodies_header());
  for (std::size_t i = 0; i < rows; ++i) {
    std::vector<std::string> fields;
    std::string row = kGoodBody;
    for (std::size_t at = 0;;) {
      const std::size_t comma = row.find(',', at);
      fields.push_back(row.substr(at, comma - at));
      if (comma == std::string::npos) break;
      at = comma + 1;
    }
    for (const auto& [r, k, t] : changes) {
      if (r == i) fields[k] = t;
    }
    for (std::size_t k = 0; k < fields.size(); ++k) text += fields[k] + (k + 1 < fields.size() ? "," : "\n");
  }
  return text;
}

/// The values of a CSV text's data rows, column by column: each field's
/// double (strtod, the double nearest the text), no rule checked, so that a
/// file that breaks one can be written in another format.
std::vector<std::vector<double>> raw_columns(const std::string& text) {
  std::vector<std::vector<double>> columns;
  std::size_t at = text.find('\n') + 1;
  while (at < text.size()) {
    const std::size_t end = text.find('\n', at);
    const std::string line = text.substr(at, end - at);
    std::size_t k = 0;
    for (std::size_t f = 0;; ++k) {
      const std::size_t comma = line.find(',', f);
      if (columns.size() <= k) columns.emplace_back();
      columns[k].push_back(std::strtod(line.substr(f, comma - f).c_str(), nullptr));
      if (comma == std::string::npos) break;
      f = comma + 1;
    }
    at = end + 1;
  }
  return columns;
}

/// A binary bodies file ('<f8') or contacts file (ids '<u4') of the raw
/// columns of a CSV text.
std::string raw_npz(const std::string& text, bool contacts) {
  const std::vector<std::vector<double>> columns = raw_columns(text);
  std::vector<std::vector<std::uint32_t>> ids;
  ids.reserve(2);  // a and b: their data stays where the columns point
  std::vector<collide::NpzColumn> out;
  for (std::size_t k = 0; k < columns.size(); ++k) {
    const std::string_view name = contacts ? collide::kContactColumns[k] : collide::kBodyColumns[k];
    if (contacts && k < 2) {
      ids.emplace_back(columns[k].begin(), columns[k].end());
      out.push_back({name, collide::NpyType::u4, ids.back().data(), ids.back().size()});
    } else {
      out.push_back({name, collide::NpyType::f8, columns[k].data(), columns[k].size()});
    }
  }
  return collide::format_npz(out);
}

/// The refusal of a bodies text by every body route in float: the CSV reader
/// (both paths), the .npz reader from the '<f8' file of its doubles (rules
/// checked by the loader, or by SolveBodies), and narrow_bodies on those
/// doubles. All must be `want`.
void expect_every_float_route_refuses(const fs::path& dir, const std::string& text, const Refusal& want) {
  const std::string csv = (dir / "bodies.csv").string();
  const std::string npz = (dir / "bodies.npz").string();
  write_text(csv, text);
  write_text(npz, raw_npz(text, false));
  std::string blanks;
  for (const char c : text) blanks += c == ',' ? std::string(" ,") : std::string(1, c);
  EXPECT_EQ(scene_refusal([&] { (void)collide::read_bodies<float>(csv); }), want) << "CSV";
  EXPECT_EQ(scene_refusal([&] { (void)collide::parse_bodies<float>(blanks, "b"); }), want) << "CSV, careful path";
  EXPECT_EQ(scene_refusal([&] { (void)collide::load_bodies<float>(npz, SceneFormat::npz); }), want) << "npz";
  EXPECT_EQ(scene_refusal([&] {
              const auto loaded = collide::load_bodies<float>(npz, SceneFormat::npz, BodyRules::by_caller);
              const collide::SolveBodies<float> s(loaded);
            }),
            want)
      << "npz, rules by the caller";
  const std::vector<std::vector<double>> raw = raw_columns(text);
  BodyColumns<double> wide;
  wide.count = raw[0].size();
  for (std::size_t k = 0; k < wide.column.size(); ++k) wide.column[k] = raw[k].data();
  BodyTable<float> table;
  const std::optional<collide::RowDefect> d = collide::narrow_bodies(wide, table);
  ASSERT_TRUE(d.has_value()) << "narrow_bodies";
  EXPECT_EQ((Refusal{d->row, std::string(d->defect.column), d->defect.reason}), want) << "narrow_bodies";
}

TEST_F(SceneRoutes, ADoubleBeyondFloatIsRefusedByEveryRouteWithOneMessage) {
  // 2^128 - 2^103: float's largest plus half its spacing; it rounds to inf.
  const double edge = std::ldexp(1.0, 128) - std::ldexp(1.0, 103);
  EXPECT_TRUE(std::isinf(static_cast<float>(edge)));
  EXPECT_EQ(static_cast<float>(std::nextafter(edge, 0.0)), std::numeric_limits<float>::max());
  const std::string reason = "value 3.4028235677973366e+38 is out of the range of float";
  constexpr std::size_t kVx = 11, kM = 0, kPx = 8;
  // The double itself; text a little below it (its nearest float would be
  // the largest, its nearest double is the edge); and a mass, which inf
  // would make immovable.
  for (const std::string& t : {std::string("3.4028235677973366e+38"), std::string("3.4028235677973365e38"),
                               std::string("-340282356779733661637539395458142568448")}) {
    const std::string r = t[0] == '-' ? "value -3.4028235677973366e+38 is out of the range of float" : reason;
    expect_every_float_route_refuses(dir_, bodies_text(3, {{1, kVx, t}}), Refusal{1, "vx", r});
    expect_every_float_route_refuses(dir_, bodies_text(3, {{2, kM, t}}), Refusal{2, "m", r});
  }
  // In row order: a broken rule in an earlier row first; in one row, the
  // value out of range before the rules, the first column first.
  expect_every_float_route_refuses(dir_, bodies_text(3, {{0, kM, "-1"}, {1, kVx, "1e39"}}),
                                   Refusal{0, "m", "mass must be > 0, got -1"});
  expect_every_float_route_refuses(dir_, bodies_text(3, {{1, kM, "-1"}, {1, kVx, "1e39"}}),
                                   Refusal{1, "vx", "value 1e+39 is out of the range of float"});
  expect_every_float_route_refuses(dir_, bodies_text(3, {{1, kPx, "-2e38"}, {1, kVx, "1e39"}, {2, kM, "1e40"}}),
                                   Refusal{1, "vx", "value 1e+39 is out of the range of float"});
  expect_every_float_route_refuses(dir_, bodies_text(3, {{1, kVx, "1e39"}, {1, kPx + 1, "4e38"}}),
                                   Refusal{1, "py", "value 4e+38 is out of the range of float"});
  // The largest double below the edge is the largest float: accepted.
  const std::string below = collide::test::shortest_text(std::nextafter(edge, 0.0));
  const BodyTable<float> t = collide::parse_bodies<float>(bodies_text(1, {{0, kM, below}}), "b");
  EXPECT_EQ(t.column[0][0], std::numeric_limits<float>::max());
}

TEST_F(SceneRoutes, AContactValueBeyondFloatIsRefusedByEveryRouteWithOneMessage) {
  const auto contacts = [](const std::string& row1, const std::string& row2) {
    return std::string(collide::contacts_header()) + "0,1,0,0,0,0,0,1,0.5,0\n" + row1 + "\n" + row2 + "\n";
  };
  const std::string csv = (dir_ / "contacts.csv").string();
  const std::string npz = (dir_ / "contacts.npz").string();
  const auto refusals = [&](const std::string& text) {
    write_text(csv, text);
    write_text(npz, raw_npz(text, true));
    return std::array<Refusal, 2>{
        scene_refusal([&] { (void)collide::read_contacts<float>(csv, 3); }),
        scene_refusal([&] { (void)collide::load_contacts<float>(npz, SceneFormat::npz, 3); })};
  };
  for (const auto& [text, want] : {std::pair{contacts("1,2,0,4e38,0,0,0,1,0.5,0", "0,2,0,0,0,0,0,1,0.5,0"),
                                             Refusal{1, "cy", "value 4e+38 is out of the range of float"}},
                                   std::pair{contacts("1,2,0,0,0,0,0,1,1.5,0", "0,2,-4e38,0,0,0,0,1,0.5,0"),
                                             Refusal{1, "e", "e must be in [0, 1], got 1.5"}},
                                   std::pair{contacts("1,2,0,0,4e38,0,0,1,1.5,0", "0,2,0,0,0,0,0,1,0.5,0"),
                                             Refusal{1, "cz", "value 4e+38 is out of the range of float"}}}) {
    const auto got = refusals(text);
    EXPECT_EQ(got[0], want) << "CSV";
    EXPECT_EQ(got[1], want) << "npz";
  }
}

TEST_F(SceneRoutes, SubnormalsTheRulesRefuseAreRefusedByEveryRouteWithOneMessage) {
  constexpr std::size_t kM = 0, kIy = 2, kQw = 4, kQx = 5;
  // A mass whose float is subnormal: its inverse overflows float. The
  // reason shows the float's value, whichever text gave it.
  expect_every_float_route_refuses(dir_, bodies_text(2, {{1, kM, "1e-40"}}),
                                   Refusal{1, "m", "mass 1e-40 is too small: its inverse overflows float"});
  // Text above the midpoint of two subnormal floats whose double is the
  // midpoint: the float is the even one.
  const float sub = std::bit_cast<float>(std::uint32_t{0x00012344});  // even
  const std::string above = collide::test::value_text(sub, ValueText::above_midpoint);
  ASSERT_TRUE(collide::test::roundings_part(above));
  expect_every_float_route_refuses(
      dir_, bodies_text(2, {{1, kIy, above}}),
      Refusal{1, "Iy",
              "moment of inertia " + collide::test::shortest_text(sub) + " is too small: its inverse overflows float"});
  // A mass that rounds to 0 in float.
  expect_every_float_route_refuses(dir_, bodies_text(2, {{1, kM, "1e-46"}}),
                                   Refusal{1, "m", "mass must be > 0, got 0 (an immovable body has m = inf)"});
  // A quaternion whose |q|^2 is subnormal in float.
  expect_every_float_route_refuses(
      dir_, bodies_text(2, {{1, kQw, "1e-20"}, {1, kQx, "3e-21"}}),
      Refusal{1, "qw",
              "quaternion cannot be normalised in float: it is too close to zero (qw, qx, qy, qz = 1e-20, 3e-21, 0, "
              "0)"});
}

}  // namespace
