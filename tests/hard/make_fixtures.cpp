// make_fixtures.cpp - regenerates the data/hard/ fixtures.
//
//   make_fixtures <repo>/data/hard
//
// Writes, for each family below, <family>/bodies.csv and contacts.csv (the
// scene) and expected_bodies.csv and expected_impulses.csv (what the law
// gives, from the high-precision path). Built by CMake, never run by ctest:
// the fixtures are committed and test_hard_fixtures.cpp holds `collide solve`
// to them; rerun this only when a family or the law changes.
//
// Why the fixtures look the way they do:
// * The scenes are the hard-case families of collide/eval/hard_scenes.hpp drawn in
//   float and written exactly (shortest round trip of the float value, read
//   back as double it is the same number), so the file means the same scene
//   to a float and a double run (q and n are stored as read; the law
//   normalises them inside the evaluation).
// * The expected outputs are reference_solve<long double> (the world-frame
//   transcription of the law, in input order) on the scene exactly as
//   `collide solve --precision double` reads it (read_bodies, to_body_buffer,
//   read_contacts), rounded to double and written with scene_io's writers.
// * The families are those whose scenes currently meet the documented bound
//   (docs/collision-law.md lists the ones that do not); 60 to 200 contacts
//   each, so the files stay small.
#include <cstdio>
#include <exception>
#include <filesystem>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "collide/eval/hard_scenes.hpp"
#include "collide/eval/reference.hpp"
#include "collide/io/scene.hpp"
#include "collide/io/scene_io.hpp"

namespace {

using L = long double;
using collide::Model;
using collide::SceneRecords;

struct Fixture {
  const char* name;
  std::function<SceneRecords<float>()> build;
};

const std::vector<Fixture>& fixtures() {
  using namespace collide::hard;
  static const std::vector<Fixture> list = {
      {"mass-ratio", [] { return mass_ratio_family<float>(100, Model::rigid, 41); }},
      {"immovable", [] { return immovable_family<float>(90, Model::rigid, 42); }},
      {"grazing", [] { return grazing_family<float>(100, Model::sphere, 43); }},
      {"unit-scales", [] { return unit_scale_family<float>(100, Model::rigid, 44); }},
      {"separating-resting", [] { return separating_resting_family<float>(60, Model::rigid, 45); }},
      {"restitution", [] { return restitution_family<float>(100, Model::particle, 46); }},
      {"spin-dominated", [] { return spin_family<float>(100, Model::rigid, 47); }},
      {"cradle",
       [] {
         return cradle_scene<float>(12, {1, 0, 0}, true, true, false, 48);
       }},
      {"star", [] { return star_scene<float>(150, false, Model::sphere, 49); }},
      {"cluster", [] { return cluster_scene<float>(30, 1.0, Model::rigid, 50); }},
  };
  return list;
}

void write_text(const std::string& path, const std::string& text) {
  collide::OutputFile out(path);
  out.write(text);
  out.commit();
}

void write_fixture(const std::filesystem::path& dir, const SceneRecords<float>& scene) {
  std::filesystem::create_directories(dir);
  std::string bodies(collide::bodies_header());
  for (const auto& b : scene.bodies) collide::append_body_row<double>(bodies, collide::detail::narrow<double>(b));
  std::string contacts(collide::contacts_header());
  for (const auto& c : scene.contacts) {
    collide::append_contact_row<double>(contacts, collide::detail::narrow<double>(c));
  }
  write_text((dir / "bodies.csv").string(), bodies);
  write_text((dir / "contacts.csv").string(), contacts);

  // The expected outputs: the scene as `collide solve --precision double`
  // reads it, solved by the long double reference.
  const collide::BodyTable<double> table = collide::read_bodies<double>((dir / "bodies.csv").string());
  const collide::ContactBuffer<double> read =
      collide::read_contacts<double>((dir / "contacts.csv").string(), table.size());
  const collide::BodyBuffer<double> start = collide::to_body_buffer(table);
  collide::BodyBuffer<L> ref_bodies = collide::convert_bodies<L>(start.view());
  const collide::ContactBuffer<L> ref_contacts = collide::convert_contacts<L>(read.view());
  collide::ImpulseBuffer<L> ref_j(read.size());
  collide::reference_solve<L>(ref_bodies.view(), ref_contacts.view(), ref_j.view());

  const collide::BodyBuffer<double> solved = collide::convert_bodies<double>(std::as_const(ref_bodies).view());
  collide::ImpulseBuffer<double> j(read.size());
  for (std::size_t k = 0; k < read.size(); ++k) {
    j.view().j.x[k] = static_cast<double>(ref_j.view().j.x[k]);
    j.view().j.y[k] = static_cast<double>(ref_j.view().j.y[k]);
    j.view().j.z[k] = static_cast<double>(ref_j.view().j.z[k]);
  }
  write_text((dir / "expected_bodies.csv").string(), collide::format_bodies<double>(table, solved.view()));
  write_text((dir / "expected_impulses.csv").string(), collide::format_impulses<double>(std::as_const(j).view()));
  std::printf("%s: %zu bodies, %zu contacts\n", dir.string().c_str(), scene.bodies.size(), scene.contacts.size());
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: make_fixtures <repo>/data/hard\n");
    return 2;
  }
  try {
    for (const Fixture& f : fixtures()) write_fixture(std::filesystem::path(argv[1]) / f.name, f.build());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "make_fixtures: %s\n", e.what());
    return 1;
  }
  return 0;
}
