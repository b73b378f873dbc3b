// hard_scenes.cpp - the catalogue of the hard-case scene families
// (collide/eval/hard_scenes.hpp): each family at its canonical seed, built
// by name, and the caller's rounding of directions applied to any scene.
//
// Design notes
// ------------
// * The scenes by name, apart from the families themselves
//   (eval/src/hard_scenes/: the draws, the pairs at extreme values, the
//   pairs on the law's boundaries, the shared-body scenes), so that the
//   report, the fixture generator and the tests name a scene the same way,
//   and the seeds tests/hard/ holds are written in one place.
// * off_unit_directions belongs to no family: it changes what any scene's
//   caller hands over, not what makes the scene hard.
#include "collide/eval/hard_scenes.hpp"

#include <array>
#include <initializer_list>
#include <stdexcept>
#include <string>
#include <vector>

namespace collide::hard {

std::vector<HardScene> hard_scene_catalogue() {
  const Model all[] = {Model::particle, Model::sphere, Model::rigid};
  std::vector<HardScene> c;
  auto pairs = [&](const char* family, std::initializer_list<Model> fits, bool float_only = false) {
    for (const Model fit : fits) c.push_back({family, fit, false, float_only});
  };
  pairs("mass-ratio", {all[0], all[1], all[2]});
  pairs("immovable", {all[0], all[1], all[2]});
  pairs("needle", {Model::rigid});
  pairs("long-lever", {Model::sphere, Model::rigid});
  pairs("grazing", {all[0], all[1], all[2]});
  pairs("unit-scales", {all[0], all[1], all[2]});
  pairs("subnormal", {all[0], all[1], all[2]}, true);
  pairs("separating-resting", {all[0], all[1], all[2]});
  pairs("e-0-and-1", {all[0], all[1], all[2]});
  pairs("stick-slip", {all[0], all[1], all[2]});
  pairs("spin-dominated", {Model::sphere, Model::rigid});
  for (const char* family : {"cradle", "cradle-mixed"}) {
    c.push_back({family, Model::particle, true, false});  // along an axis
    c.push_back({family, Model::sphere, true, false});    // along a random axis
  }
  for (const char* family : {"star", "star-fixed-hub", "cluster"}) {
    for (const Model fit : all) c.push_back({family, fit, true, false});
  }
  return c;
}

template <class T>
SceneRecords<T> off_unit_directions(SceneRecords<T> records, std::uint64_t seed) {
  SceneRng rng(seed);
  for (ContactRecord<T>& c : records.contacts) {
    const double scale = 1 + rng.uniform(-9e-4, 9e-4);
    for (T& x : c.n) x = static_cast<T>(static_cast<double>(x) * scale);
  }
  for (BodyRecord<T>& b : records.bodies) {
    const double scale = rng.log_uniform(0.5, 2.0);
    for (T& x : b.q) x = static_cast<T>(static_cast<double>(x) * scale);
  }
  return records;
}

template <class T>
Scene<T> build_hard_scene(const HardScene& scene, std::size_t count) {
  // The seeds of tests/hard/, so that the report shows the scenes the tests hold.
  const std::string& f = scene.family;
  const Model fit = scene.fit;
  if (f == "mass-ratio") return mass_ratio_family<T>(count, fit, 11).scene();
  if (f == "immovable") return immovable_family<T>(count, fit, 12).scene();
  if (f == "needle") return needle_family<T>(count, 13).scene();
  if (f == "long-lever") return long_lever_family<T>(count, fit, 14).scene();
  if (f == "grazing") return grazing_family<T>(count, fit, 15).scene();
  if (f == "unit-scales") return unit_scale_family<T>(count, fit, 16).scene();
  if (f == "subnormal") return subnormal_family<T>(count, fit, 17).scene();
  if (f == "separating-resting") return separating_resting_family<T>(count, fit, 18).scene();
  if (f == "e-0-and-1") return restitution_family<T>(count, fit, 19).scene();
  if (f == "stick-slip") return stick_slip_family<T>(count, fit, 20).scene();
  if (f == "spin-dominated") return spin_family<T>(count, fit, 21).scene();
  if (f == "cradle" || f == "cradle-mixed") {
    // Axis-aligned for particles; otherwise test_hard_shared's random axis.
    std::array<double, 3> axis = {1, 0, 0};
    if (fit != Model::particle) axis = SceneRng(31).unit_vector();
    const bool classic = f == "cradle";
    return cradle_scene<T>(20, axis, classic, classic, false, classic ? 32 : 33).scene();
  }
  if (f == "star" || f == "star-fixed-hub") return star_scene<T>(1000, f == "star-fixed-hub", fit, 34).scene();
  if (f == "cluster") return cluster_scene<T>(80, 1.0, fit, 35).scene();
  throw std::invalid_argument("unknown hard family '" + f + "'");
}

#define COLLIDE_CATALOGUE(T)                                                       \
  template SceneRecords<T> off_unit_directions<T>(SceneRecords<T>, std::uint64_t); \
  template Scene<T> build_hard_scene<T>(const HardScene&, std::size_t);
COLLIDE_CATALOGUE(float)
COLLIDE_CATALOGUE(double)
#undef COLLIDE_CATALOGUE

}  // namespace collide::hard
