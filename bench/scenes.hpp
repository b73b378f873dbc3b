// bench/scenes.hpp - the scenes the rows of collide_bench solve: which they
// are, how they are generated or read, and the one prepared scene kept alive
// at a time with its pristine velocities, schedule and memory figures.
//
// Design notes
// ------------
// * Scenes: pairs (collide::generate_pairs: contact k joins bodies 2k,
//   2k + 1), debris (collide::generate_debris: N/2 movable bodies shared at
//   random plus one immovable ground under 25% of the contacts), pairs+mu
//   (pairs with friction), pile and pile+shuffle (collide::generate_pile:
//   boxes on a lattice, each in about six contacts, the bottom layer on a
//   ground, the contacts in broadphase cell order or shuffled), chain
//   (collide::generate_chain: N contacts between N + 1 boxes in a
//   staircase, no ground, so the schedule is one batch per contact and the
//   law runs sequentially) and file (the scene of --scene, read as `collide solve`
//   reads it). N counts contacts: a pile's N is the contact count of the
//   largest pile within the size asked (pile_size), so that its rows' rates
//   count the contacts solved.
// * A scene is generated once per (scene, precision, N, model, friction) and
//   shared by the rows that follow; only one scene is alive at a time (at
//   N = 16M in double a pairs scene is ~6 GB), so registration keeps the rows
//   of one scene together.
// * Every timed solve starts from the same velocities: a solve changes v and
//   w, and a second solve of the same scene would see separating contacts,
//   which a branching scalar path resolves more cheaply. Prepared keeps a
//   copy of v and w and restores it (memcpy, untimed) before each solve.
// * A scene that does not fit in the last-level cache is solved cold: after
//   the restore, which would leave up to an LLC of dirty velocity lines for
//   the timed solve to write back and a tail of warm lines, 4x the LLC is
//   streamed through the caches (untimed), as a large scene starts every
//   frame; the rows' label says "cold caches", since `collide report` does
//   not stream them. A scene that fits in the LLC is solved warm, which is
//   what it would be.
// * Memory: when a scene is prepared, its buffers are generated, the peak RSS
//   is reset (/proc/self/clear_refs), the schedule is built and one 2-thread
//   SIMD solve runs; the growth of the peak over the RSS before is what the
//   kernel costs beyond the caller's buffers (MemoryRecord, compared in the
//   summary with the budget of 16 bytes per contact plus 8 per body).
#pragma once

#include <array>
#include <cstddef>
#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

#include "collide/bodies.hpp"
#include "collide/contacts.hpp"
#include "collide/io/scene.hpp"
#include "collide/model.hpp"
#include "collide/schedule.hpp"
#include "support.hpp"

namespace collide_bench {

enum class Kind { pairs, debris, pairs_mu, pile, pile_shuffled, chain, file };

/// The scene's part of a row name: "pairs", "debris", "pairs+mu", "pile",
/// "pile+shuffle", "chain", "file".
const char* kind_name(Kind kind);

/// Whether the scene is a pile (its N is a pile's contact count).
constexpr bool is_pile(Kind kind) { return kind == Kind::pile || kind == Kind::pile_shuffled; }

/// The contact count of the largest pile with at most `contacts` contacts.
std::size_t pile_size(std::size_t contacts);

/// The precision's part of a row name: "f32" or "f64", the rows' spelling of
/// collide::precision_name<T>() (collide/rules.hpp), which names it in
/// messages. The rows run float and double only.
template <class T>
constexpr const char* precision_tag() {
  static_assert(std::is_same_v<T, float> || std::is_same_v<T, double>, "the rows run float or double");
  return std::is_same_v<T, float> ? "f32" : "f64";
}

/// The files of --scene (Kind::file): bodies and contacts, CSV or binary
/// (.npz) by name.
void set_scene_files(std::string bodies, std::string contacts);
/// The contacts of the --scene contacts file, its N. Throws the reader's
/// error (std::exception) on a bad file.
std::size_t scene_file_contacts();

struct SceneKey {
  Kind kind = Kind::pairs;
  std::size_t precision_bytes = 0;
  std::size_t n = 0;
  collide::Model model = collide::Model::rigid;  // the body model the scene's bodies fit
  bool friction = false;                         // mu drawn (always for Kind::pairs_mu)
  bool operator==(const SceneKey& o) const {
    return kind == o.kind && precision_bytes == o.precision_bytes && n == o.n && model == o.model &&
           friction == o.friction;
  }
};

/// Memory facts of one prepared scene, kept for the summary.
struct MemoryRecord {
  std::string scene;  // "pairs/f32/n:16777216"
  std::size_t contacts = 0, bodies = 0;
  double buffer_bytes = 0;    // the caller's buffers: bodies, contacts, impulses
  double bench_bytes = 0;     // the bench's own: saved v and w, cache-evict buffer
  double schedule_bytes = 0;  // Schedule::memory_bytes()
  double extra_bytes = 0;     // peak RSS growth over building the schedule and one solve
  double peak_rss_bytes = 0;  // VmHWM after that
  bool peak_was_reset = false;
};

/// Every scene prepared so far, in order.
const std::vector<MemoryRecord>& memory_records();

/// A scene ready to solve: buffers, the pristine velocities, the schedule.
template <class T>
struct Prepared {
  SceneKey key;
  collide::Scene<T> scene;
  collide::ImpulseBuffer<T> impulses;
  std::vector<T> saved;  // v.x, v.y, v.z, w.x, w.y, w.z of every body, back to back
  collide::Schedule schedule;
  bool friction = false;
  bool exceeds_llc = false;

  collide::BodyView<T> bodies() { return scene.bodies.view(); }
  collide::ContactView<T> contacts() const { return scene.contacts.view(); }

  // v.x, v.y, v.z, w.x, w.y, w.z: the arrays a solve writes.
  std::array<T*, 6> velocity_arrays() {
    const collide::BodyView<T> b = bodies();
    return {b.v.x, b.v.y, b.v.z, b.w.x, b.w.y, b.w.z};
  }
  void save() {
    const std::size_t nb = scene.bodies.size();
    saved.resize(6 * nb);
    const std::array<T*, 6> arrays = velocity_arrays();
    for (std::size_t i = 0; i < 6; ++i) {
      std::memcpy(saved.data() + i * nb, arrays[i], nb * sizeof(T));
    }
  }
  void restore() {
    const std::size_t nb = scene.bodies.size();
    const std::array<T*, 6> arrays = velocity_arrays();
    for (std::size_t i = 0; i < 6; ++i) {
      std::memcpy(arrays[i], saved.data() + i * nb, nb * sizeof(T));
    }
  }
  /// Untimed preparation of the next timed solve (see the design notes).
  void reset_for_solve() {
    restore();
    if (exceeds_llc) {
      evict_caches();
    }
  }
};

/// A fresh scene of `kind` with `n` contacts and rigid bodies (the file's
/// scene for Kind::file, whatever `n`).
template <class T>
collide::Scene<T> generate(Kind kind, std::size_t n);

/// The prepared scene of the key, from the cache when it is the one alive,
/// else prepared after the one alive is freed.
template <class T>
Prepared<T>& prepared_scene(Kind kind, std::size_t n, collide::Model model = collide::Model::rigid,
                            bool friction = false);

}  // namespace collide_bench
