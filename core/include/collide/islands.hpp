// collide/islands.hpp - the islands of a scene: the groups of contacts that
// share movable bodies, directly or through one another.
//
// Design notes
// ------------
// The law applies the contacts of a movable body one after another, in input
// order (schedule.hpp); contacts that reach no common movable body, even
// through others, never see each other's results. The connected components
// of the contact graph over movable bodies (an edge per contact between its
// two bodies; immovable bodies, inverse mass 0, are left out of the graph, as
// the schedule leaves them out of its conflicts) are therefore independent
// scenes: solving each island on its own, with its contacts in input order,
// gives bit for bit the result of one solve of the whole scene, in any order
// of the islands, on any machine. That is what lets a scene be split between
// processes or machines (the Python package's collide.dask), and what stops
// it: the contacts of one island form one sequential chain of dependencies,
// however many there are.
//
// * Every contact belongs to exactly one island: the island of its movable
//   bodies, or, when both of its bodies are immovable, an island of its own
//   (its impulse is 0 and it moves nothing). A movable body with contacts
//   belongs to the island of its contacts; an immovable body belongs to none
//   (a ground under a thousand boxes joins none of them to another), nor does
//   a body without contacts.
// * Labels do not depend on the thread count or on the order the threads ran
//   in: island i is the island whose first contact, in input order, comes
//   i-th among the islands' first contacts. So contact 0 is in island 0, and
//   labels grow with the contacts that open them.
// * Built in parallel: a lock-free union-find over the movable bodies (each
//   contact between two movable bodies links their roots, the larger index
//   under the smaller with a compare-and-swap, so the trees never cycle and
//   a root is the smallest body index of its island), then parallel passes
//   for each island's first contact (an atomic minimum), its label (a prefix
//   count over contacts in chunks) and its size. The chunks follow
//   Schedule::build: at most `threads` of them, none smaller than 32k items.
// * Memory: the result (4 bytes per contact, per body and per island) and
//   4 bytes per body of scratch.
//
// The header is C++17, like the rest of the public API.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

#include "collide/bodies.hpp"
#include "collide/contacts.hpp"
#include "collide/labels.hpp"
#include "collide/packed.hpp"

namespace collide {

/// The islands of a contact set (islands()).
struct Islands {
  /// The label of no island: an immovable body, or a body without contacts.
  static constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
  /// The island of each contact, in input order: 0 .. count() - 1, numbered
  /// in the order of the islands' first contacts.
  Labels contact_island;
  /// The island of each body, or kNone (immovable, or without contacts).
  Labels body_island;
  /// The number of contacts of each island.
  Labels island_contacts;
  /// Contacts of the largest island (0 without contacts).
  std::size_t largest = 0;
  /// The label of the largest island (the first of that size); 0 without contacts.
  std::size_t largest_island = 0;

  /// Number of islands.
  [[nodiscard]] std::size_t count() const { return island_contacts.size(); }
};

/// The islands of `contacts` over bodies of which those with inverse mass 0
/// are immovable: body i's inverse mass is inv_mass[i]. `threads`: at most
/// this many threads, in the calling thread's task arena; 0 means that
/// arena's concurrency. The result does not depend on it.
///
/// Checked in every build type, before an index is used (validate_indices(),
/// collide/validate.hpp): every index < body_count and a != b;
/// std::invalid_argument naming the first contact that breaks it
/// ("collide::islands: contacts.b[17] = 40: out of range (8 bodies)"). Also
/// std::invalid_argument for threads < 0 or a null array with a count > 0,
/// and std::length_error for 2^32 - 1 contacts or bodies or more (labels are
/// 32-bit, kNone reserved). The values are not checked: that is validate()'s.
template <class T>
Islands islands(const ContactView<T>& contacts, std::size_t body_count, const T* inv_mass, int threads = 0);

/// The same for any SoA body view (BodyView, SphereView, ParticleView, of T
/// or of const T): only its count and inverse masses are read.
template <class T, template <class> class View>
Islands islands(const ContactView<T>& contacts, const View<T>& bodies, int threads = 0) {
  return islands(contacts, bodies.count, static_cast<const T*>(bodies.inv_mass), threads);
}

template <class T, template <class> class View>
Islands islands(const ContactView<T>& contacts, const View<const T>& bodies, int threads = 0) {
  return islands(contacts, bodies.count, bodies.inv_mass, threads);
}

/// The same on packed rigid records: the inverse masses beside them.
template <class T>
Islands islands(const ContactView<T>& contacts, const PackedView<PackedRigid<T>>& bodies, int threads = 0) {
  return islands(contacts, bodies.count, static_cast<const T*>(bodies.inv_mass), threads);
}

/// The same on packed sphere and particle records: the inverse masses read
/// in place from the records, one record apart.
template <class T>
Islands islands_strided(const ContactView<T>& contacts, std::size_t body_count, const T* inv_mass, std::size_t stride,
                        int threads);
template <class Record>
Islands islands(const ContactView<typename PackedValue<Record>::type>& contacts, const PackedView<Record>& bodies,
                int threads = 0) {
  using T = typename PackedValue<Record>::type;
  const T* inv_mass = bodies.count != 0 && bodies.bodies != nullptr ? &bodies.bodies->inv_mass : nullptr;
  return islands_strided(contacts, bodies.count, inv_mass, sizeof(Record) / sizeof(T), threads);
}

extern template Islands islands<float>(const ContactView<float>&, std::size_t, const float*, int);
extern template Islands islands<double>(const ContactView<double>&, std::size_t, const double*, int);
extern template Islands islands_strided<float>(const ContactView<float>&, std::size_t, const float*, std::size_t, int);
extern template Islands islands_strided<double>(const ContactView<double>&, std::size_t, const double*, std::size_t,
                                                int);

}  // namespace collide
