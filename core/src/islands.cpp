// islands.cpp - the islands of islands.hpp, in six parallel passes (three
// when no movable body is in two contacts: single_contact_islands).
//
// 1. Parents (over bodies): parent[i] = i for a movable body, kNone for an
//    immovable one, which no contact links to anything.
// 2. Union (over contacts): a contact between two movable bodies links the
//    roots of their trees, the larger root under the smaller, by a
//    compare-and-swap that succeeds only while the larger is still a root
//    (else both roots are found again). Parents only ever decrease, so no
//    thread can close a cycle, and the final sets are the connected
//    components whatever the interleaving; a find halves the path it walks
//    (a parent replaced by its own parent is still an ancestor, so a stale
//    value is harmless).
// 3. Roots (over bodies): parent[i] becomes the root itself, so every later
//    pass reads a body's island in one load.
// 4. First contacts (over contacts): first[root] = the smallest contact of
//    the root's island (an atomic minimum, the same for every interleaving).
//    A contact with no movable body is its own island and its own first.
// 5. Labels (over contacts, in chunks): each chunk counts the first
//    contacts in it, a prefix over the chunks gives each chunk its first
//    label, and each chunk numbers its first contacts in input order: the
//    labels of a sequential scan. Then every contact takes the label of its
//    island's first contact (written by the previous pass only, so no
//    contact reads a label being written).
// 6. Sizes (over contacts) and body labels (over bodies): counts added per
//    run of consecutive contacts of one island (one atomic add per run, so a
//    giant island does not make every thread fight over one counter), and
//    each movable body with contacts takes its root's label.
//
// Memory: the arrays are allocated uninitialised (LabelAllocator) in 2 MiB
// pages; each pass writes what a later one reads, so the pages are first
// touched in parallel by the pass that fills them, rather than zeroed first
// on one thread (docs/decisions/0023-fresh-arrays-touched-where-they-are-written.md).
//
// The atomics are std::atomic_ref (C++20) over plain vectors, relaxed: the
// union-find's correctness rests on the compare-and-swap alone, and every
// pass ends at a tbb::parallel_for join, which orders it before the next.
#include "collide/islands.hpp"

#include <algorithm>
#include <atomic>
#include <cassert>
#include <cstdlib>
#include <limits>
#include <new>
#include <numeric>
#include <stdexcept>
#include <string>

#include <oneapi/tbb/task_arena.h>

#include "chunks.hpp"
#include "collide/validate.hpp"
#include "repeated_bodies.hpp"

namespace collide {
namespace {

constexpr std::uint32_t kNone = Islands::kNone;

using Ref = std::atomic_ref<std::uint32_t>;

/// Chunks of a range: at most `workers` of them, none smaller than
/// detail::kMinChunk items, run by detail::for_each_chunk.
struct Chunks {
  std::size_t items = 0;
  std::size_t count = 1;

  Chunks(std::size_t n, std::size_t workers) : items(n), count(detail::chunk_count(n, workers)) {}

  /// f(chunk, begin, end) over every chunk.
  template <class F>
  void run(const F& f) const {
    detail::for_each_chunk(items, count, f);
  }
};

/// The root of x's tree, halving the path on the way: each visited body's
/// parent becomes its grandparent, if nobody changed it meanwhile.
std::uint32_t find_root(std::uint32_t* parent, std::uint32_t x) {
  for (;;) {
    const std::uint32_t p = Ref(parent[x]).load(std::memory_order_relaxed);
    if (p == x) return x;
    const std::uint32_t g = Ref(parent[p]).load(std::memory_order_relaxed);
    // Parents decrease towards the root. Checked on the values read: a
    // failed compare-and-swap below would load parent[x] as another thread
    // left it, possibly already below g.
    assert(g <= p && p < x);
    if (g != p) {
      std::uint32_t expected = p;
      Ref(parent[x]).compare_exchange_weak(expected, g, std::memory_order_relaxed);
    }
    x = g;
  }
}

/// Joins the trees of x and y: the larger root goes under the smaller one,
/// only while it is still a root.
void unite(std::uint32_t* parent, std::uint32_t x, std::uint32_t y) {
  for (;;) {
    std::uint32_t rx = find_root(parent, x);
    std::uint32_t ry = find_root(parent, y);
    if (rx == ry) return;
    if (rx < ry) std::swap(rx, ry);
    std::uint32_t expected = rx;
    if (Ref(parent[rx]).compare_exchange_strong(expected, ry, std::memory_order_relaxed)) return;
    // rx was linked by another thread meanwhile: find both roots again.
  }
}

/// The root of contact k's island: its movable body's root (after pass 3
/// every parent is a root), or kNone when both bodies are immovable.
inline std::uint32_t contact_root(const std::uint32_t* parent, BodyIndex a, BodyIndex b) {
  const std::uint32_t ra = parent[a];
  return ra != kNone ? ra : parent[b];
}

/// Contacts whose movable bodies are in no other contact (the pairs scene)
/// are each an island of their own, numbered as they come: whether that is
/// so, and then `out` filled, in three passes instead of six. Each contact
/// writes its number into its movable bodies' labels (failing at a label an
/// earlier contact of its chunk wrote); then each contact checks that its
/// bodies still carry its number: of two contacts that wrote one body, the
/// later write stands and the other sees it, in any order or interleaving
/// of the chunks.
/// Immovable bodies are never written and keep kNone. On false, `out` is
/// half written and the caller starts over.
template <class T>
bool single_contact_islands(const BodyIndex* a, const BodyIndex* b, std::size_t m, const T* inv_mass,
                            std::size_t stride, const Chunks& body_chunks, const Chunks& contact_chunks, Islands& out) {
  std::vector<std::uint32_t> scratch;
  if (m == 0 || detail::movable_body_repeats(a, b, std::min(m, detail::kRepeatProbe), inv_mass, stride, scratch)) {
    return false;
  }
  std::uint32_t* const body = out.body_island.data();
  body_chunks.run([&](std::size_t, std::size_t begin, std::size_t end) { std::fill(body + begin, body + end, kNone); });
  constexpr std::size_t kBlock = 4096;  // contacts between looks at `failed`
  std::atomic<bool> failed{false};
  contact_chunks.run([&](std::size_t, std::size_t begin, std::size_t end) {
    // Another chunk's number is overwritten, not a failure: the check
    // below then finds the body shared whichever chunk ran first.
    const auto claim = [&](BodyIndex i, std::uint32_t k) {
      if (is_immovable(inv_mass[i * stride])) return true;
      Ref slot(body[i]);
      const std::uint32_t seen = slot.load(std::memory_order_relaxed);
      if (seen >= begin && seen < k) return false;  // a repeat within the chunk
      slot.store(k, std::memory_order_relaxed);
      return true;
    };
    for (std::size_t k = begin; k < end; ++k) {
      if (k % kBlock == 0 && failed.load(std::memory_order_relaxed)) return;
      const auto kk = static_cast<std::uint32_t>(k);
      if (!claim(a[k], kk) || !claim(b[k], kk)) {
        failed.store(true, std::memory_order_relaxed);
        return;
      }
    }
  });
  if (failed.load(std::memory_order_relaxed)) return false;
  out.island_contacts.resize(m);
  std::uint32_t* const label = out.contact_island.data();
  std::uint32_t* const sizes = out.island_contacts.data();
  contact_chunks.run([&](std::size_t, std::size_t begin, std::size_t end) {
    bool own = true;
    for (std::size_t k = begin; k < end; ++k) {
      const auto kk = static_cast<std::uint32_t>(k);
      const std::uint32_t la = Ref(body[a[k]]).load(std::memory_order_relaxed);
      const std::uint32_t lb = Ref(body[b[k]]).load(std::memory_order_relaxed);
      own &= (la == kk || la == kNone) & (lb == kk || lb == kNone);
      label[k] = kk;
      sizes[k] = 1;
    }
    if (!own) failed.store(true, std::memory_order_relaxed);
  });
  if (failed.load(std::memory_order_relaxed)) return false;
  out.largest = 1;
  out.largest_island = 0;
  return true;
}

void check_arguments(std::size_t contact_count, const BodyIndex* a, const BodyIndex* b, std::size_t body_count,
                     const void* inv_mass, int threads) {
  const std::string who = "collide::islands: ";
  if (threads < 0) throw std::invalid_argument(who + "threads must be >= 0, got " + std::to_string(threads));
  if (contact_count >= kNone) {
    throw std::length_error(who + std::to_string(contact_count) + " contacts; islands label at most 2^32 - 2");
  }
  if (body_count >= kNone) {
    throw std::length_error(who + std::to_string(body_count) + " bodies; islands label at most 2^32 - 2");
  }
  if (contact_count > 0 && (a == nullptr || b == nullptr)) {
    throw std::invalid_argument(
        who + "contacts.a or contacts.b is null but contacts.count = " + std::to_string(contact_count));
  }
  if (body_count > 0 && inv_mass == nullptr) {
    throw std::invalid_argument(who + "bodies.inv_mass is null but bodies.count = " + std::to_string(body_count));
  }
  if (const Validation v = validate_indices(a, b, contact_count, body_count); !v) {
    throw std::invalid_argument(who + v.message);
  }
}

}  // namespace

template <class T>
Islands islands_strided(const ContactView<T>& contacts, std::size_t body_count, const T* inv_mass, std::size_t stride,
                        int threads) {
  const std::size_t m = contacts.count;
  const BodyIndex* const a = contacts.a;
  const BodyIndex* const b = contacts.b;
  check_arguments(m, a, b, body_count, inv_mass, threads);
  const std::size_t workers = threads > 0
                                  ? static_cast<std::size_t>(threads)
                                  : static_cast<std::size_t>(std::max(1, tbb::this_task_arena::max_concurrency()));
  const Chunks body_chunks(body_count, workers);
  const Chunks contact_chunks(m, workers);

  // The arrays are not zeroed (LabelAllocator): every pass below writes
  // what it reads later, in parallel, which is also where their pages are
  // first touched.
  Islands out;
  out.contact_island.resize(m);
  out.body_island.resize(body_count);
  if (single_contact_islands(a, b, m, inv_mass, stride, body_chunks, contact_chunks, out)) return out;

  // Pass 1. body_island is the union-find's parent array until pass 6
  // turns it into labels.
  Labels first;  // pass 4's, set to kNone here
  first.resize(body_count);
  std::uint32_t* const parent = out.body_island.data();
  body_chunks.run([&](std::size_t, std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      parent[i] = is_immovable(inv_mass[i * stride]) ? kNone : static_cast<std::uint32_t>(i);
      first[i] = kNone;
    }
  });

  // Pass 2.
  contact_chunks.run([&](std::size_t, std::size_t begin, std::size_t end) {
    for (std::size_t k = begin; k < end; ++k) {
      // Relaxed loads: other threads link roots meanwhile, but a body's
      // movability (kNone or not) never changes.
      const bool movable_a = Ref(parent[a[k]]).load(std::memory_order_relaxed) != kNone;
      if (movable_a && Ref(parent[b[k]]).load(std::memory_order_relaxed) != kNone) unite(parent, a[k], b[k]);
    }
  });

  // Pass 3. Reading while others write: every value read is an ancestor,
  // and the walk ends at the same root.
  body_chunks.run([&](std::size_t, std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      Ref slot(parent[i]);
      if (slot.load(std::memory_order_relaxed) != kNone) {
        slot.store(find_root(parent, static_cast<std::uint32_t>(i)), std::memory_order_relaxed);
      }
    }
  });

  // Pass 4.
  contact_chunks.run([&](std::size_t, std::size_t begin, std::size_t end) {
    for (std::size_t k = begin; k < end; ++k) {
      const std::uint32_t r = contact_root(parent, a[k], b[k]);
      if (r == kNone) continue;
      Ref slot(first[r]);
      std::uint32_t seen = slot.load(std::memory_order_relaxed);
      const auto kk = static_cast<std::uint32_t>(k);
      while (kk < seen && !slot.compare_exchange_weak(seen, kk, std::memory_order_relaxed)) {
      }
    }
  });

  // Pass 5: first contacts numbered in input order, then every contact.
  std::uint32_t* const label = out.contact_island.data();
  const auto opens = [&](std::size_t k) {
    const std::uint32_t r = contact_root(parent, a[k], b[k]);
    return r == kNone || first[r] == k;
  };
  std::vector<std::uint32_t> chunk_first(contact_chunks.count + 1, 0);
  contact_chunks.run([&](std::size_t c, std::size_t begin, std::size_t end) {
    std::uint32_t n = 0;
    for (std::size_t k = begin; k < end; ++k) n += static_cast<std::uint32_t>(opens(k));
    chunk_first[c + 1] = n;
  });
  for (std::size_t c = 0; c < contact_chunks.count; ++c) chunk_first[c + 1] += chunk_first[c];
  const std::size_t island_count = chunk_first[contact_chunks.count];
  assert(island_count <= m && (m == 0 || island_count > 0));
  contact_chunks.run([&](std::size_t c, std::size_t begin, std::size_t end) {
    std::uint32_t next = chunk_first[c];
    for (std::size_t k = begin; k < end; ++k) {
      if (opens(k)) label[k] = next++;
    }
  });
  contact_chunks.run([&](std::size_t, std::size_t begin, std::size_t end) {
    for (std::size_t k = begin; k < end; ++k) {
      const std::uint32_t r = contact_root(parent, a[k], b[k]);
      if (r != kNone && first[r] != k) label[k] = label[first[r]];
    }
  });

  // Pass 6.
  out.island_contacts.resize(island_count);
  std::uint32_t* const sizes = out.island_contacts.data();
  Chunks(island_count, workers).run([&](std::size_t, std::size_t begin, std::size_t end) {
    std::fill(sizes + begin, sizes + end, 0u);
  });
  contact_chunks.run([&](std::size_t, std::size_t begin, std::size_t end) {
    std::size_t k = begin;
    while (k < end) {
      const std::uint32_t l = label[k];
      assert(l < island_count);
      const std::size_t run_start = k;
      while (k < end && label[k] == l) ++k;
      Ref(sizes[l]).fetch_add(static_cast<std::uint32_t>(k - run_start), std::memory_order_relaxed);
    }
  });
  body_chunks.run([&](std::size_t, std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      const std::uint32_t r = parent[i];
      parent[i] = r == kNone || first[r] == kNone ? kNone : label[first[r]];
    }
  });
  // Every contact counted once, in one island.
  assert(std::accumulate(sizes, sizes + island_count, std::size_t{0}) == m);
  if (island_count > 0) {
    const std::uint32_t* const largest = std::max_element(sizes, sizes + island_count);
    out.largest = *largest;
    out.largest_island = static_cast<std::size_t>(largest - sizes);
  }
  return out;
}

template <class T>
Islands islands(const ContactView<T>& contacts, std::size_t body_count, const T* inv_mass, int threads) {
  return islands_strided(contacts, body_count, inv_mass, 1, threads);
}

template Islands islands<float>(const ContactView<float>&, std::size_t, const float*, int);
template Islands islands<double>(const ContactView<double>&, std::size_t, const double*, int);
template Islands islands_strided<float>(const ContactView<float>&, std::size_t, const float*, std::size_t, int);
template Islands islands_strided<double>(const ContactView<double>&, std::size_t, const double*, std::size_t, int);

}  // namespace collide
