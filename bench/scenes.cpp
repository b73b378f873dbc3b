// bench/scenes.cpp - generating, reading and preparing the scenes of
// collide_bench, one alive at a time (design notes in scenes.hpp).
#include "scenes.hpp"

#include <malloc.h>

#include <memory>
#include <string>
#include <utility>

#include "collide/eval/traffic.hpp"
#include "collide/io/generate.hpp"
#include "collide/io/scene_npz.hpp"
#include "collide/rules.hpp"
#include "collide/solve.hpp"
#include "row_names.hpp"

namespace collide_bench {
namespace {

/// The scene files of --scene (Kind::file).
struct SceneFiles {
  std::string bodies, contacts;
};
SceneFiles g_files;

std::vector<MemoryRecord> g_memory;

template <class T>
collide::Scene<T> generate(const SceneKey& key) {
  if (key.kind == Kind::file) {
    // Read, not drawn: every rule checked as `collide solve` checks it.
    const auto bodies = collide::load_bodies<T>(g_files.bodies, collide::scene_format_of(g_files.bodies));
    const auto contacts =
        collide::load_contacts<T>(g_files.contacts, collide::scene_format_of(g_files.contacts), bodies.size());
    collide::Scene<T> scene;
    scene.bodies = collide::to_body_buffer(bodies.columns());
    scene.contacts.assign_exact(contacts.view());
    return scene;
  }
  collide::GenerateOptions options;
  options.seed = 1;
  options.friction = key.friction || key.kind == Kind::pairs_mu;
  options.model = key.model;
  if (is_pile(key.kind)) {
    options.shuffle = key.kind == Kind::pile_shuffled;
    return collide::generate_pile<T>(collide::pile_side_for_contacts(key.n), options);
  }
  if (key.kind == Kind::chain) {
    return collide::generate_chain<T>(key.n, options);
  }
  return key.kind == Kind::debris ? collide::generate_debris<T>(key.n, options)
                                  : collide::generate_pairs<T>(key.n, options);
}

/// Holds the one scene alive at a time.
class SceneCache {
 public:
  template <class T>
  Prepared<T>& get(Kind kind, std::size_t n, collide::Model model, bool friction) {
    const SceneKey key{kind, sizeof(T), n, model, friction};
    std::unique_ptr<Prepared<T>>& slot = this->slot<T>();
    if (slot && slot->key == key) {
      return *slot;
    }
    // Free the old scene before generating the new one: at 16M both would
    // not fit side by side in double.
    float_.reset();
    double_.reset();
    // Hand freed heap back to the system so that the next scene's RSS and
    // peak start from what is really in use.
    malloc_trim(0);
    slot = prepare<T>(key);
    return *slot;
  }

 private:
  template <class T>
  std::unique_ptr<Prepared<T>>& slot() {
    if constexpr (sizeof(T) == 4) {
      return float_;
    } else {
      return double_;
    }
  }

  template <class T>
  static std::unique_ptr<Prepared<T>> prepare(const SceneKey& key) {
    auto p = std::make_unique<Prepared<T>>();
    p->key = key;
    p->scene = generate<T>(key);
    p->friction = p->scene.contacts.view().mu != nullptr;
    p->impulses.resize(key.n);
    p->save();
    const std::size_t bodies = p->scene.bodies.size();
    p->exceeds_llc = static_cast<double>(key.n) *
                         static_cast<double>(collide::bytes_per_collision(key.model, sizeof(T), p->friction)) >
                     static_cast<double>(llc_bytes());

    MemoryRecord record;
    record.scene = std::string(kind_name(key.kind)) + "/" + precision_tag<T>() + "/n:" + std::to_string(key.n);
    if (key.model != collide::Model::rigid || key.friction) {
      record.scene += '/';
      record.scene += model_tag(key.model, key.friction);
    }
    record.contacts = key.n;
    record.bodies = bodies;
    record.buffer_bytes = static_cast<double>(bodies * 17 * sizeof(T)) +
                          static_cast<double>(key.n) * (2 * sizeof(collide::BodyIndex) + 8 * sizeof(T)) +
                          static_cast<double>(key.n * 3 * sizeof(T));
    record.bench_bytes = static_cast<double>(p->saved.size() * sizeof(T) + evict_buffer_bytes());
    const double rss_before = status_bytes("VmRSS");
    record.peak_was_reset = reset_peak_rss();
    p->schedule.build(p->contacts(), p->bodies());
    {
      collide::SolverOptions options;
      options.path = collide::Path::simd;
      options.threads = 2;
      collide::Solver solver(options);
      solver.solve(p->bodies(), p->contacts(), p->impulses.view(), p->schedule);
    }
    p->restore();
    record.peak_rss_bytes = status_bytes("VmHWM");
    record.extra_bytes = record.peak_rss_bytes - rss_before;
    record.schedule_bytes = static_cast<double>(p->schedule.memory_bytes());
    g_memory.push_back(record);
    return p;
  }

  std::unique_ptr<Prepared<float>> float_;
  std::unique_ptr<Prepared<double>> double_;
};

SceneCache g_cache;

}  // namespace

const char* kind_name(Kind kind) {
  switch (kind) {
    case Kind::pairs:
      return "pairs";
    case Kind::debris:
      return "debris";
    case Kind::pairs_mu:
      return "pairs+mu";
    case Kind::pile:
      return "pile";
    case Kind::pile_shuffled:
      return "pile+shuffle";
    case Kind::chain:
      return "chain";
    case Kind::file:
      return "file";
  }
  return "?";
}

std::size_t pile_size(std::size_t contacts) {
  return collide::pile_contact_count(collide::pile_side_for_contacts(contacts));
}

void set_scene_files(std::string bodies, std::string contacts) { g_files = {std::move(bodies), std::move(contacts)}; }

std::size_t scene_file_contacts() {
  return collide::load_contacts<double>(g_files.contacts, collide::scene_format_of(g_files.contacts),
                                        collide::kUnknownBodyCount)
      .size();
}

const std::vector<MemoryRecord>& memory_records() { return g_memory; }

template <class T>
collide::Scene<T> generate(Kind kind, std::size_t n) {
  return generate<T>(SceneKey{kind, sizeof(T), n});
}

template <class T>
Prepared<T>& prepared_scene(Kind kind, std::size_t n, collide::Model model, bool friction) {
  return g_cache.get<T>(kind, n, model, friction);
}

template collide::Scene<float> generate<float>(Kind, std::size_t);
template collide::Scene<double> generate<double>(Kind, std::size_t);
template Prepared<float>& prepared_scene<float>(Kind, std::size_t, collide::Model, bool);
template Prepared<double>& prepared_scene<double>(Kind, std::size_t, collide::Model, bool);

}  // namespace collide_bench
