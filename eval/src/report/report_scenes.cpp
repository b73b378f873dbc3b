// report/report_scenes.cpp - the scenes the rows of the report run on: the
// generated pairs, debris and pile scenes (make_scene), the caller's scene
// files (read_scene_files), the first contacts of a scene as a scene of
// their own (contact_prefix), the sphere and particle scenes derived from
// the rigid one (derive_model), and the size of the error sample.
//
// Design notes
// ------------
// * Apart from the Runner (run_report.cpp): preparing a scene is not
//   measuring it. Nothing here is timed; the Runner asks for a scene of a
//   kind, a size and a seed, and times only the solves.
// * The templates are instantiated here for float and double, the
//   precisions of the rows, as measure.cpp does for its own.
#include <algorithm>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "collide/io/generate.hpp"
#include "collide/io/scene.hpp"
#include "collide/io/scene_io.hpp"
#include "collide/io/scene_npz.hpp"
#include "collide/model.hpp"
#include "report.hpp"
#include "report_run.hpp"

namespace collide::report_detail {

std::size_t report_sample_size(const ReportOptions& config) {
  if (!config.quick) return config.sample;
  return std::min({config.sample, config.n, config.debris_n, config.pile_n});
}

const char* scene_name(SceneKind kind) {
  switch (kind) {
    case SceneKind::pairs:
      return "pairs";
    case SceneKind::debris:
      return "debris";
    case SceneKind::pile:
      return "pile";
    case SceneKind::file:
      break;
  }
  return "file";
}

template <class T>
Scene<T> read_scene_files(const std::string& bodies_path, const std::string& contacts_path) {
  const LoadedBodies<T> bodies = load_bodies<T>(bodies_path, scene_format_of(bodies_path));
  const LoadedContacts<T> contacts = load_contacts<T>(contacts_path, scene_format_of(contacts_path), bodies.size());
  Scene<T> scene;
  scene.bodies = to_body_buffer(bodies.columns());
  scene.contacts.assign_exact(contacts.view());
  return scene;
}

template <class T>
Scene<T> contact_prefix(const Scene<T>& scene, std::size_t k) {
  const ContactView<T> c = scene.contacts.view();
  const BodyView<const T> b = scene.bodies.view();
  k = std::min(k, c.count);
  std::vector<BodyIndex> id(b.count, std::numeric_limits<BodyIndex>::max());
  std::vector<BodyIndex> used;
  const auto renumber = [&](BodyIndex i) {
    if (id[i] == std::numeric_limits<BodyIndex>::max()) {
      id[i] = static_cast<BodyIndex>(used.size());
      used.push_back(i);
    }
    return id[i];
  };
  Scene<T> out;
  out.contacts.resize(k);
  for (std::size_t j = 0; j < k; ++j) {
    ContactRecord<T> r = scene.contacts.record(j);
    r.a = renumber(r.a);
    r.b = renumber(r.b);
    out.contacts.set(j, r);
  }
  out.bodies.resize(used.size());
  for (std::size_t i = 0; i < used.size(); ++i) out.bodies.set(i, scene.bodies.record(used[i]));
  return out;
}

template <class T>
Scene<T> make_scene(SceneKind kind, std::size_t n, bool friction, std::uint64_t seed) {
  GenerateOptions options;
  options.seed = seed;
  options.friction = friction;
  if (kind == SceneKind::pile) return generate_pile<T>(pile_side_for_contacts(n), options);
  return kind == SceneKind::pairs ? generate_pairs<T>(n, options) : generate_debris<T>(n, options);
}

template <class T>
void derive_model(Scene<T>& scene, Model model) {
  BodyView<T> b = scene.bodies.view();
  for (std::size_t i = 0; i < b.count; ++i) {
    if (model == Model::sphere) {
      b.inv_inertia.y[i] = b.inv_inertia.x[i];
      b.inv_inertia.z[i] = b.inv_inertia.x[i];
    } else if (model == Model::particle) {
      b.inv_inertia.x[i] = b.inv_inertia.y[i] = b.inv_inertia.z[i] = T(0);
      b.w.x[i] = b.w.y[i] = b.w.z[i] = T(0);
    }
  }
  if (const std::string misfit = model_misfit(model, b, scene.contacts.view()); !misfit.empty()) {
    throw std::logic_error(std::string("derived ") + to_string(model) + " scene does not fit: " + misfit);
  }
}

template Scene<float> read_scene_files<float>(const std::string&, const std::string&);
template Scene<double> read_scene_files<double>(const std::string&, const std::string&);
template Scene<float> contact_prefix<float>(const Scene<float>&, std::size_t);
template Scene<double> contact_prefix<double>(const Scene<double>&, std::size_t);
template Scene<float> make_scene<float>(SceneKind, std::size_t, bool, std::uint64_t);
template Scene<double> make_scene<double>(SceneKind, std::size_t, bool, std::uint64_t);
template void derive_model<float>(Scene<float>&, Model);
template void derive_model<double>(Scene<double>&, Model);

}  // namespace collide::report_detail
