// kernel/loops.hpp - the kernel's loops for one lane width: they gather
// contacts and bodies into lanes, run the kernel body of contact_kernel.hpp
// and scatter the results. Each loop is one named function for one choice of
// body model, precision, accuracy mode, friction and body layout (or one of
// the run's loops), and kernel_table.hpp's tables point at them. Included by
// the kernel units, one per body model, precision and accuracy mode
// (kernel/units.hpp), compiled once per ISA with COLLIDE_KERNEL_NS naming it,
// and by the one-lane unit (kernel/scalar.cpp), compiled for the baseline
// (core/CMakeLists.txt).
//
// Design notes
// ------------
// * A range is processed W contacts at a time; the last (count mod W)
//   contacts run through the one-lane loop of the same choices (the
//   baseline's, kernel/scalar.cpp). Same operations, same order, no FMA: the
//   tail is bitwise what a lane would have produced, on every ISA.
// * Contiguous batches (every scene without shared movable bodies, like the
//   pairs scene) load contact fields as vectors; only the first index of
//   each group is read from `order`.
// * Immovable bodies are gathered but never written: many lanes may read the
//   one ground body at once, none writes it.
// * Everything here is in an anonymous namespace: a unit's loops have
//   internal linkage, so no object defines a weak (vague-linkage) function
//   that another could take (tests/core/test_isa_objects.sh), and a unit
//   holds only the loops its model's slots point at. The loops themselves
//   are never inlined (they are reached only through the table); what they
//   call is forced inline (lanes.hpp), as it was when one object held every
//   loop.
// * Nothing here allocates, spawns or locks: threads are the driver's
//   (solve.cpp); this file is arithmetic and memory only.
#pragma once

#ifndef COLLIDE_KERNEL_NS
#error "kernel/loops.hpp is compiled once per ISA with COLLIDE_KERNEL_NS set (core/CMakeLists.txt)"
#endif

#include <algorithm>
#include <cassert>
#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <utility>
#include <variant>

#include "collide/model.hpp"
#include "contact_kernel.hpp"
#include "kernel_table.hpp"
#include "record_lanes.hpp"

#ifndef COLLIDE_PREFETCH_AHEAD
#define COLLIDE_PREFETCH_AHEAD 32
#endif

namespace collide::detail {
inline namespace COLLIDE_KERNEL_NS {
namespace {

/// Where the W contacts of a group come from: consecutive indices starting at
/// `first` (contiguous batch) or the W indices at `index`.
struct ContactGroup {
  bool contiguous;
  std::uint32_t first;
  const std::uint32_t* index;
};

template <class V, class T>
COLLIDE_LANE_INLINE V contact_field(const T* field, const ContactGroup& g) {
  return g.contiguous ? load<V>(field + g.first) : gather<V>(field, g.index);
}

/// Calls f(field, lane_of_a, lane_of_b) for every field the model writes (the
/// velocities, ArrayRole::velocity): the lanes of `a` and `b` are read into
/// (BodyLanes) or written from (const BodyLanes).
template <class M, class View, class Lanes, class F>
COLLIDE_LANE_INLINE void velocity_fields(const View& view, Lanes& a, Lanes& b, F&& f) {
  for_each_lane_field<View>([&](auto at) COLLIDE_LANE_LAMBDA {
    using At = decltype(at);
    if constexpr (At::field.role == ArrayRole::velocity) f(At::of(view), At::of(a), At::of(b));
  });
}

/// Calls f(field, lane_of_a, lane_of_b) for every input field of the model,
/// so that the index gather and the paired load share one field list (the
/// model's table); then forms a rigid body's rotation from q.
template <class M, class V, bool kVelocities = true, class View, class F>
COLLIDE_LANE_INLINE void read_bodies(const View& view, BodyLanes<M, V>& a, BodyLanes<M, V>& b, F&& f) {
  // Not the velocities for the geometry of a run (run_geometry): its walk reads them.
  for_each_lane_field<View>([&](auto at) COLLIDE_LANE_LAMBDA {
    using At = decltype(at);
    if constexpr (kVelocities || At::field.role != ArrayRole::velocity) f(At::of(view), At::of(a), At::of(b));
    // The rotation as soon as q is in, while its lanes are in registers.
    if constexpr (At::field.member == BodyMember::q && At::field.component == 3) {
      a.rotation = normalised_rotation(a.q);
      b.rotation = normalised_rotation(b.q);
    }
  });
}

/// Calls f(field, lane_of_a, lane_of_b) for every field the model writes.
template <class M, class V, class View, class F>
COLLIDE_LANE_INLINE void write_bodies(const View& view, const BodyLanes<M, V>& a, const BodyLanes<M, V>& b, F&& f) {
  velocity_fields<M>(view, a, b, f);
}

/// How the bodies of a group lie in the SoA arrays, which decides how they
/// are read and written:
/// * paired: contact l joins bodies first + 2l and first + 2l + 1, so both
///   sides come from 2W consecutive bodies (two vector loads and a
///   deinterleave per field, instead of 2W scalar loads). This is how a
///   caller lays out independent pairs, how the pairs scene is built, and
///   one colour of a chain or of a pile's x contacts in the colour order;
/// * runs: the a bodies are W consecutive bodies, and so are the b bodies
///   (one vector load per side and field): a pile's y and z contacts, one
///   colour of them after another, in the colour order;
/// * gathered: anything else, W scalar loads per side and field.
enum class BodyStreams { gathered, paired, runs };

template <std::size_t W>
COLLIDE_LANE_INLINE BodyStreams body_streams(const BodyIndex* ia, const BodyIndex* ib) {
  bool paired = true;
  bool runs = true;
  for (std::size_t l = 0; l < W; ++l) {
    paired &= (ia[l] == ia[0] + 2 * l) & (ib[l] == ia[l] + 1);
    runs &= (ia[l] == ia[0] + l) & (ib[l] == ib[0] + l);
  }
  return paired ? BodyStreams::paired : runs ? BodyStreams::runs : BodyStreams::gathered;
}

/// True for the SoA views (BodyView, SphereView, ParticleView: one array per
/// component), false for a PackedView of records.
template <class View>
inline constexpr bool kSoaLayout = true;
template <class Record>
inline constexpr bool kSoaLayout<PackedView<Record>> = false;

/// The bodies ia[0..W) and ib[0..W) into lanes by index: gathers from the
/// SoA arrays, or row loads and transposes from packed records (whose rows
/// hold the velocities whatever kVelocities says).
template <class M, class V, class T, bool kVelocities = true, class View>
COLLIDE_LANE_INLINE void gather_bodies(const View& bodies, const BodyIndex* ia, const BodyIndex* ib, BodyLanes<M, V>& a,
                                       BodyLanes<M, V>& b) {
  if constexpr (kSoaLayout<View>) {
    read_bodies<M, V, kVelocities>(bodies, a, b, [&](const T* field, V& la, V& lb) COLLIDE_LANE_LAMBDA {
      la = gather<V>(field, ia);
      lb = gather<V>(field, ib);
    });
  } else {
    read_records<M, V>(bodies, ia, a);
    read_records<M, V>(bodies, ib, b);
  }
}

/// The bodies of a group's contacts: their indices, and how they lie in the
/// SoA arrays (BodyStreams).
template <std::size_t W>
struct GroupBodies {
  BodyIndex a[W];
  BodyIndex b[W];
  BodyStreams streams = BodyStreams::gathered;
};

template <class V, class T, class View>
COLLIDE_LANE_INLINE GroupBodies<V::size()> group_bodies([[maybe_unused]] const View& bodies,
                                                        const ContactView<T>& contacts, const ContactGroup& g) {
  constexpr std::size_t W = V::size();
  GroupBodies<W> at;
  for (std::size_t l = 0; l < W; ++l) {
    const std::uint32_t k = g.contiguous ? g.first + static_cast<std::uint32_t>(l) : g.index[l];
    at.a[l] = contacts.a[k];
    at.b[l] = contacts.b[k];
    assert(at.a[l] < bodies.count && at.b[l] < bodies.count && at.a[l] != at.b[l]);
  }
  // Only the SIMD path looks for streams; the scalar path (W = 1) would gain
  // nothing. The arithmetic is the same either way. The packed layout has
  // no such shortcut (its records are already contiguous per body).
  if constexpr (kSoaLayout<View> && W > 1) at.streams = body_streams<W>(at.a, at.b);
  return at;
}

/// Calls f(field, lane_of_a, lane_of_b) for every field a group's load
/// reads: every field the law reads, or with kOnlyVelocities the velocities
/// alone (the velocity step, whose geometry is formed).
template <class M, class V, bool kOnlyVelocities, class View, class F>
COLLIDE_LANE_INLINE void loaded_fields(const View& bodies, BodyLanes<M, V>& a, BodyLanes<M, V>& b, F&& f) {
  if constexpr (kOnlyVelocities) {
    velocity_fields<M>(bodies, a, b, f);
  } else {
    read_bodies<M, V>(bodies, a, b, f);
  }
}

/// A paired group's bodies (BodyStreams::paired): two vector loads and a
/// deinterleave per field.
template <class M, class V, class T, bool kOnlyVelocities, class View>
COLLIDE_LANE_INLINE void load_paired(const View& bodies, const GroupBodies<V::size()>& at, BodyLanes<M, V>& a,
                                     BodyLanes<M, V>& b) {
  loaded_fields<M, V, kOnlyVelocities>(bodies, a, b, [&](const T* field, V& la, V& lb) COLLIDE_LANE_LAMBDA {
    load_deinterleaved(field + at.a[0], la, lb);
  });
}

/// The group's bodies from the SoA arrays by the load its BodyStreams name.
template <class M, class V, class T, bool kOnlyVelocities, class View>
COLLIDE_LANE_INLINE void load_streams(const View& bodies, const GroupBodies<V::size()>& at, BodyLanes<M, V>& a,
                                      BodyLanes<M, V>& b) {
  if (at.streams == BodyStreams::paired) {
    load_paired<M, V, T, kOnlyVelocities>(bodies, at, a, b);
  } else if (at.streams == BodyStreams::runs) {
    loaded_fields<M, V, kOnlyVelocities>(bodies, a, b, [&](const T* field, V& la, V& lb) COLLIDE_LANE_LAMBDA {
      la = load<V>(field + at.a[0]);
      lb = load<V>(field + at.b[0]);
    });
  } else {
    loaded_fields<M, V, kOnlyVelocities>(bodies, a, b, [&](const T* field, V& la, V& lb) COLLIDE_LANE_LAMBDA {
      la = gather<V>(field, at.a);
      lb = gather<V>(field, at.b);
    });
  }
}

/// load_streams as a call, for the SIMD kernels' full loads. Where the three
/// loads meet inside the law's function, the AVX-512 kernel's 32 registers
/// cannot hold both sides' lanes and it spills inside the law (decision
/// 0033); called, the loaded lanes pass through memory once, into the law's
/// first loads, which costs less (decision 0035). Pairs never come here
/// (their loop knows they are paired), and the velocity step's six fields
/// are too few to spill.
template <class M, class V, class T, class View>
__attribute__((noinline)) void load_streams_out_of_line(const View& bodies, const GroupBodies<V::size()>& at,
                                                        BodyLanes<M, V>& a, BodyLanes<M, V>& b) {
  load_streams<M, V, T, false>(bodies, at, a, b);
}

/// The group's bodies into lanes (loaded_fields); a packed record's rows
/// come whole either way.
///
/// With kPaired the caller knows the group is paired, and only that load is
/// compiled (see solve_groups).
template <class M, class V, class T, bool kOnlyVelocities = false, bool kPaired = false, class View>
COLLIDE_LANE_INLINE void load_group_bodies(const View& bodies, const GroupBodies<V::size()>& at, BodyLanes<M, V>& a,
                                           BodyLanes<M, V>& b) {
  if constexpr (kPaired) {
    load_paired<M, V, T, kOnlyVelocities>(bodies, at, a, b);
  } else if constexpr (kSoaLayout<View> && V::size() > 1 && !kOnlyVelocities) {
    load_streams_out_of_line<M, V, T>(bodies, at, a, b);
  } else if constexpr (kSoaLayout<View>) {
    load_streams<M, V, T, kOnlyVelocities>(bodies, at, a, b);
  } else {
    read_records<M, V>(bodies, at.a, a);
    read_records<M, V>(bodies, at.b, b);
  }
}

/// The velocities the law left in the lanes, back to the group's bodies.
/// An immovable body is never written, not even with its own value: another
/// thread may be reading it (the ground is in many contacts of a batch).
template <class M, class V, class T, bool kPaired = false, class View>
COLLIDE_LANE_INLINE void store_group_bodies(const View& bodies, const GroupBodies<V::size()>& at,
                                            const BodyLanes<M, V>& a, const BodyLanes<M, V>& b) {
  const auto movable_a = a.inv_mass != V(0);
  const auto movable_b = b.inv_mass != V(0);
  if constexpr (kSoaLayout<View>) {
    // Whole vectors only when every body is movable: a's and b's bodies are
    // then all distinct, and no immovable one is written.
    if (at.streams != BodyStreams::gathered && stdx::all_of(movable_a && movable_b)) {
      if (kPaired || at.streams == BodyStreams::paired) {
        write_bodies<M, V>(bodies, a, b, [&](T* field, const V& la, const V& lb) COLLIDE_LANE_LAMBDA {
          store_interleaved(la, lb, field + at.a[0]);
        });
      } else {
        write_bodies<M, V>(bodies, a, b, [&](T* field, const V& la, const V& lb) COLLIDE_LANE_LAMBDA {
          store(la, field + at.a[0]);
          store(lb, field + at.b[0]);
        });
      }
      return;
    }
    write_bodies<M, V>(bodies, a, b, [&](T* field, const V& la, const V& lb) COLLIDE_LANE_LAMBDA {
      scatter(la, field, at.a, movable_a);
      scatter(lb, field, at.b, movable_b);
    });
  } else {
    // a's records first, then b's: within a group no movable body repeats,
    // so the order of the stores cannot matter.
    write_records<M, V>(bodies, at.a, a, movable_a);
    write_records<M, V>(bodies, at.b, b, movable_b);
  }
}

/// The group's J to the impulse arrays, or with `accumulate` added to what
/// they hold (a later pass).
template <class V, class T>
COLLIDE_LANE_INLINE void store_group_impulses(const ImpulseView<T>& impulses, const ContactGroup& g, Vec3<V> j,
                                              bool accumulate) {
  if (g.contiguous) {
    if (accumulate) {
      j = summed_impulse(
          Vec3<V>{load<V>(impulses.j.x + g.first), load<V>(impulses.j.y + g.first), load<V>(impulses.j.z + g.first)},
          j);
    }
    store(j.x, impulses.j.x + g.first);
    store(j.y, impulses.j.y + g.first);
    store(j.z, impulses.j.z + g.first);
  } else {
    if (accumulate) {
      j = summed_impulse(
          Vec3<V>{gather<V>(impulses.j.x, g.index), gather<V>(impulses.j.y, g.index), gather<V>(impulses.j.z, g.index)},
          j);
    }
    const auto all = V(0) == V(0);
    scatter(j.x, impulses.j.x, g.index, all);
    scatter(j.y, impulses.j.y, g.index, all);
    scatter(j.z, impulses.j.z, g.index, all);
  }
}

/// Resolves one group of V::size() contacts; with `accumulate`, adds J to
/// the impulses there (a later pass).
template <class M, class V, bool kFriction, class Mode, bool kPaired, class T, class View>
COLLIDE_LANE_INLINE void solve_group(const View& bodies, const ContactView<T>& contacts, const ImpulseView<T>& impulses,
                                     const ContactGroup& g, const GroupBodies<V::size()>& at, bool accumulate) {
  BodyLanes<M, V> a;
  BodyLanes<M, V> b;
  load_group_bodies<M, V, T, false, kPaired>(bodies, at, a, b);

  ContactLanes<V> c;
  if constexpr (kRotates<M>) {
    c.c = {contact_field<V>(contacts.c.x, g), contact_field<V>(contacts.c.y, g), contact_field<V>(contacts.c.z, g)};
  }
  c.n = {contact_field<V>(contacts.n.x, g), contact_field<V>(contacts.n.y, g), contact_field<V>(contacts.n.z, g)};
  c.e = contacts.e ? contact_field<V>(contacts.e, g) : V(contacts.uniform_e);
  if constexpr (kFriction) c.mu = contact_field<V>(contacts.mu, g);

  const ContactResult<V> r = resolve_contacts<M, V, kFriction, Mode>(a, b, c);
  store_group_bodies<M, V, T, kPaired>(bodies, at, a, b);
  store_group_impulses<V>(impulses, g, r.j, accumulate);
}

/// The totals of a group's contacts (KernelJob::accumulated), as the passes
/// before left them.
template <class V, bool kFriction, class T>
COLLIDE_LANE_INLINE Accumulated<V> load_accumulated(const AccumulatedView<T>& view, const ContactGroup& g) {
  Accumulated<V> acc;
  acc.normal = contact_field<V>(view.normal, g);
  acc.target = contact_field<V>(view.target, g);
  if constexpr (kFriction) {
    acc.friction = {contact_field<V>(view.friction[0], g), contact_field<V>(view.friction[1], g),
                    contact_field<V>(view.friction[2], g)};
  } else {
    acc.friction = {V(0), V(0), V(0)};
  }
  return acc;
}

template <class V, bool kFriction, class T>
COLLIDE_LANE_INLINE void store_accumulated(const AccumulatedView<T>& view, const ContactGroup& g,
                                           const Accumulated<V>& acc) {
  const auto put = [&](const V& value, T* field) COLLIDE_LANE_LAMBDA {
    if (g.contiguous) {
      store(value, field + g.first);
    } else {
      scatter(value, field, g.index, V(0) == V(0));
    }
  };
  put(acc.normal, view.normal);
  put(acc.target, view.target);
  if constexpr (kFriction) {
    put(acc.friction.x, view.friction[0]);
    put(acc.friction.y, view.friction[1]);
    put(acc.friction.z, view.friction[2]);
  }
}

/// One accumulated pass of one group of V::size() contacts (KernelJob::
/// accumulates): the first pass's law recording the totals, or a later
/// pass moving them; J is written, not added. A warm start's visits
/// (KernelJob::warm with first_pass) measure the targets, then apply the
/// totals, and write no J.
template <class M, class V, bool kFriction, class T, class View>
COLLIDE_LANE_INLINE void accumulate_group(const View& bodies, const KernelJob<T>& job, const ContactGroup& g) {
  const GroupBodies<V::size()> at = group_bodies<V>(bodies, job.contacts, g);
  BodyLanes<M, V> a;
  BodyLanes<M, V> b;
  load_group_bodies<M, V, T>(bodies, at, a, b);
  const ContactView<T>& contacts = job.contacts;
  ContactLanes<V> c;
  if constexpr (kRotates<M>) {
    c.c = {contact_field<V>(contacts.c.x, g), contact_field<V>(contacts.c.y, g), contact_field<V>(contacts.c.z, g)};
  }
  c.n = {contact_field<V>(contacts.n.x, g), contact_field<V>(contacts.n.y, g), contact_field<V>(contacts.n.z, g)};
  c.e = contacts.e ? contact_field<V>(contacts.e, g) : V(contacts.uniform_e);
  if constexpr (kFriction) c.mu = contact_field<V>(contacts.mu, g);
  Accumulated<V> acc;
  if (job.first_pass && job.warm != WarmVisit::none) {
    acc = load_accumulated<V, kFriction>(job.accumulated, g);
    const ContactGeometry<V> geo = contact_geometry(a, b, c);
    if (job.warm == WarmVisit::targets) {
      warm_start_target(a, b, c, geo, acc);
    } else {
      warm_start_step<M, V, kFriction>(a, b, c, geo, acc);
      store_group_bodies<M, V, T>(bodies, at, a, b);
    }
    store_accumulated<V, kFriction>(job.accumulated, g, acc);
    return;
  }
  ContactResult<V> r;
  if (job.first_pass) {
    r = first_accumulated_pass<M, V, kFriction>(a, b, c, acc);
  } else {
    acc = load_accumulated<V, kFriction>(job.accumulated, g);
    r = accumulated_pass<M, V, kFriction>(a, b, c, acc);
  }
  store_group_bodies<M, V, T>(bodies, at, a, b);
  store_group_impulses<V>(job.impulses, g, r.j, false);
  store_accumulated<V, kFriction>(job.accumulated, g, acc);
}

template <class V>
COLLIDE_LANE_INLINE Vec3<V> load3(typename V::value_type* const (&from)[3], std::size_t at) {
  return {load<V>(from[0] + at), load<V>(from[1] + at), load<V>(from[2] + at)};
}

/// The stored geometry of the contacts at position `at` (V::size() of them)
/// and their bodies' inverse masses, as contact_geometry formed them: what
/// the velocity step reads (step_group in lanes, piece_walk in one).
template <class M, class V, class T>
COLLIDE_LANE_INLINE ContactGeometry<V> stored_geometry(const GeometryView<T>& geometry, std::size_t at,
                                                       BodyLanes<M, V>& a, BodyLanes<M, V>& b) {
  a.inv_mass = load<V>(geometry.inv_mass_a + at);
  b.inv_mass = load<V>(geometry.inv_mass_b + at);
  ContactGeometry<V> g{};
  if constexpr (kRotates<M>) {
    g.ra = load3<V>(geometry.ra, at);
    g.rb = load3<V>(geometry.rb, at);
    g.arm_a = {load3<V>(geometry.response_a, at), load<V>(geometry.k_a + at)};
    g.arm_b = {load3<V>(geometry.response_b, at), load<V>(geometry.k_b + at)};
  }
  return g;
}

/// The velocity step of one group of V::size() consecutive contacts at
/// `first`, whose geometry is formed (KernelJob::stepped): the second half
/// of the law on the first half's stored values, so the bits are those of
/// solve_group (fast mode, frictionless).
template <class M, class V, class T, class View>
COLLIDE_LANE_INLINE void step_group(const View& bodies, const ContactView<T>& contacts, const ImpulseView<T>& impulses,
                                    const GeometryView<T>& geometry, std::uint32_t first, bool accumulate) {
  const ContactGroup g{true, first, nullptr};
  const GroupBodies<V::size()> at = group_bodies<V>(bodies, contacts, g);
  BodyLanes<M, V> a;
  BodyLanes<M, V> b;
  load_group_bodies<M, V, T, true>(bodies, at, a, b);
  const ContactGeometry<V> geo = stored_geometry(geometry, first, a, b);
  ContactLanes<V> c;
  c.n = {load<V>(contacts.n.x + first), load<V>(contacts.n.y + first), load<V>(contacts.n.z + first)};
  c.e = contacts.e ? load<V>(contacts.e + first) : V(contacts.uniform_e);
  ContactResult<V> r = velocity_step<M, V, false, FastMode>(a, b, c, geo);
  canonical_outputs(a, b, r.j);  // as resolve_contacts
  store_group_bodies<M, V, T>(bodies, at, a, b);
  store_group_impulses<V>(impulses, g, r.j, accumulate);
}

/// An accumulated pass of one group of V::size() consecutive contacts at
/// `first` whose geometry is formed (KernelJob::stepped, frictionless): the
/// accumulated step on the stored first half, so the bits are those of
/// accumulate_group.
template <class M, class V, class T, class View>
COLLIDE_LANE_INLINE void accumulate_step_group(const View& bodies, const KernelJob<T>& job, std::uint32_t first) {
  const ContactGroup g{true, first, nullptr};
  const GroupBodies<V::size()> at = group_bodies<V>(bodies, job.contacts, g);
  BodyLanes<M, V> a;
  BodyLanes<M, V> b;
  load_group_bodies<M, V, T, true>(bodies, at, a, b);
  const ContactGeometry<V> geo = stored_geometry(job.geometry, first, a, b);
  const ContactView<T>& contacts = job.contacts;
  ContactLanes<V> c;
  c.n = {load<V>(contacts.n.x + first), load<V>(contacts.n.y + first), load<V>(contacts.n.z + first)};
  c.e = contacts.e ? load<V>(contacts.e + first) : V(contacts.uniform_e);
  Accumulated<V> acc;
  if (job.first_pass && job.warm != WarmVisit::none) {
    acc = load_accumulated<V, false>(job.accumulated, g);
    if (job.warm == WarmVisit::targets) {
      warm_start_target(a, b, c, geo, acc);
    } else {
      warm_start_step<M, V, false>(a, b, c, geo, acc);
      store_group_bodies<M, V, T>(bodies, at, a, b);
    }
    store_accumulated<V, false>(job.accumulated, g, acc);
    return;
  }
  ContactResult<V> r;
  if (job.first_pass) {
    r = first_accumulated_step<M, V, false>(a, b, c, geo, acc);
  } else {
    acc = load_accumulated<V, false>(job.accumulated, g);
    r = accumulated_step<M, V, false>(a, b, c, geo, acc);
  }
  store_group_bodies<M, V, T>(bodies, at, a, b);
  store_group_impulses<V>(job.impulses, g, r.j, false);
  store_accumulated<V, false>(job.accumulated, g, acc);
}

/// Contacts [begin, end) of the schedule's order, all inside one batch, in
/// groups of W; returns where the groups stopped (the tail, fewer than W
/// contacts, is the caller's).
///
/// On the packed layout, the records of the contacts kPrefetchAhead
/// positions ahead are requested before each group: a record is one to three
/// lines, so the requests are few and the misses overlap instead of waiting
/// one after another. In a scattered batch the contact's own lines (its body
/// indices, fields and J) are requested twice as far ahead: the record
/// requests read the body indices, which would otherwise be a demand miss
/// of their own and stall the loop at every contact. Copying the contacts
/// into schedule order before the solve (and J back after) would do the
/// same with scratch of 56 bytes per contact and two more passes over them,
/// and was no faster (docs/decisions/0005-packed-records-for-scattered-contacts.md).
inline constexpr std::size_t kPrefetchAhead = COLLIDE_PREFETCH_AHEAD;

/// Asks for the lines of contact k's fields and of its J: a scattered batch
/// reads them from lines that hold few other contacts of the batch. The
/// contact point only when the model reads it (kPoint): a particle solve may
/// have none (contacts.c null), and offsetting a null pointer is undefined
/// even where only a prefetch uses the result.
template <bool kPoint, class T>
COLLIDE_LANE_INLINE void prefetch_contact(const ContactView<T>& c, const ImpulseView<T>& j, std::uint32_t k) {
  __builtin_prefetch(c.a + k, 0, 2);
  __builtin_prefetch(c.b + k, 0, 2);
  if constexpr (kPoint) {
    for (const T* f : {c.c.x, c.c.y, c.c.z}) __builtin_prefetch(f + k, 0, 2);
  }
  for (const T* f : {c.n.x, c.n.y, c.n.z}) __builtin_prefetch(f + k, 0, 2);
  if (c.e != nullptr) __builtin_prefetch(c.e + k, 0, 2);
  if (c.mu != nullptr) __builtin_prefetch(c.mu + k, 0, 2);
  for (T* f : {j.j.x, j.j.y, j.j.z}) __builtin_prefetch(f + k, 1, 2);
}

template <class M, class V, bool kFriction, class Mode, class T, class View>
COLLIDE_LANE_INLINE std::size_t solve_groups(const View& bodies, const ContactView<T>& contacts,
                                             const ImpulseView<T>& impulses, const std::uint32_t* order,
                                             bool contiguous, bool accumulate, std::size_t begin, std::size_t end) {
  constexpr std::size_t W = V::size();
  std::size_t i = begin;
  if constexpr (!kSoaLayout<View>) {
    if (W > 1) {
      if (!contiguous) {
        for (std::size_t k = begin; k < std::min(end, begin + 2 * kPrefetchAhead); ++k) {
          prefetch_contact<kRotates<M>>(contacts, impulses, order[k]);
        }
      }
      for (std::size_t k = begin; k < std::min(end, begin + kPrefetchAhead); ++k) {
        prefetch_record(bodies, contacts.a[order[k]]);
        prefetch_record(bodies, contacts.b[order[k]]);
      }
      for (; i + W <= end; i += W) {
        if (!contiguous) {
          for (std::size_t k = i + 2 * kPrefetchAhead; k < std::min(end, i + W + 2 * kPrefetchAhead); ++k) {
            prefetch_contact<kRotates<M>>(contacts, impulses, order[k]);
          }
        }
        for (std::size_t k = i + kPrefetchAhead; k < std::min(end, i + W + kPrefetchAhead); ++k) {
          prefetch_record(bodies, contacts.a[order[k]]);
          prefetch_record(bodies, contacts.b[order[k]]);
        }
        const ContactGroup g{contiguous, order[i], order + i};
        solve_group<M, V, kFriction, Mode, false>(bodies, contacts, impulses, g, group_bodies<V>(bodies, contacts, g),
                                                  accumulate);
      }
      return i;
    }
  }
  // Paired groups first, each law's inputs from one kind of load: where
  // the three kinds of loads meet before the law, the wide kernel's 32
  // registers cannot hold both sides' lanes and spill
  // (docs/decisions/0033-passes-on-the-velocity-step.md). Independent pairs
  // are paired from first to last; the first other group hands the rest of
  // the range to the general loop.
  if constexpr (kSoaLayout<View> && W > 1) {
    for (; i + W <= end; i += W) {
      const ContactGroup g{contiguous, order[i], order + i};
      const GroupBodies<W> at = group_bodies<V>(bodies, contacts, g);
      if (at.streams != BodyStreams::paired) break;
      solve_group<M, V, kFriction, Mode, true>(bodies, contacts, impulses, g, at, accumulate);
    }
  }
  for (; i + W <= end; i += W) {
    const ContactGroup g{contiguous, order[i], order + i};
    solve_group<M, V, kFriction, Mode, false>(bodies, contacts, impulses, g, group_bodies<V>(bodies, contacts, g),
                                              accumulate);
  }
  return i;
}

template <class V>
COLLIDE_LANE_INLINE void store3(const Vec3<V>& v, typename V::value_type* const (&to)[3], std::size_t at) {
  store(v.x, to[0] + at);
  store(v.y, to[1] + at);
  store(v.z, to[2] + at);
}

/// First pass: the geometry of the W contacts order[at], ... of a piece, in
/// lanes, from the bodies' positions, orientations and inverse masses. Their
/// velocities are not read from SoA arrays (another thread may be walking
/// the contacts before this piece, run_pipeline.hpp); a packed record's come
/// with its rows and are ignored: the walk reads them as the contacts
/// before have left them.
template <class M, class V, class T, class View>
COLLIDE_LANE_INLINE void run_geometry(const View& bodies, const ContactView<T>& contacts, const std::uint32_t* index,
                                      const GeometryView<T>& into, std::size_t at) {
  constexpr std::size_t W = V::size();
  BodyIndex ia[W];
  BodyIndex ib[W];
  for (std::size_t l = 0; l < W; ++l) {
    ia[l] = contacts.a[index[l]];
    ib[l] = contacts.b[index[l]];
    assert(ia[l] < bodies.count && ib[l] < bodies.count && ia[l] != ib[l]);
  }
  BodyLanes<M, V> a;
  BodyLanes<M, V> b;
  gather_bodies<M, V, T, false>(bodies, ia, ib, a, b);
  ContactLanes<V> c;
  if constexpr (kRotates<M>) {
    c.c = {gather<V>(contacts.c.x, index), gather<V>(contacts.c.y, index), gather<V>(contacts.c.z, index)};
  }
  c.n = {gather<V>(contacts.n.x, index), gather<V>(contacts.n.y, index), gather<V>(contacts.n.z, index)};
  const ContactGeometry<V> g = contact_geometry(a, b, c);
  store(a.inv_mass, into.inv_mass_a + at);
  store(b.inv_mass, into.inv_mass_b + at);
  if constexpr (kRotates<M>) {
    store3(g.ra, into.ra, at);
    store3(g.rb, into.rb, at);
    store3(g.arm_a.response, into.response_a, at);
    store3(g.arm_b.response, into.response_b, at);
    store(g.arm_a.k, into.k_a + at);
    store(g.arm_b.k, into.k_b + at);
  }
}

/// Body i's velocities, one lane: SoA arrays or the first values of its
/// record (record_lanes.hpp asserts that order).
template <class M, class S, class View>
COLLIDE_LANE_INLINE void read_velocities(const View& view, BodyIndex i, BodyLanes<M, S>& body) {
  using T = typename S::value_type;
  if constexpr (kSoaLayout<View>) {
    body.v = {S(view.v.x[i]), S(view.v.y[i]), S(view.v.z[i])};
    if constexpr (kRotates<M>) body.w = {S(view.w.x[i]), S(view.w.y[i]), S(view.w.z[i])};
  } else {
    const T* r = reinterpret_cast<const T*>(view.bodies + i);
    body.v = {S(r[0]), S(r[1]), S(r[2])};
    if constexpr (kRotates<M>) body.w = {S(r[3]), S(r[4]), S(r[5])};
  }
}
template <class M, class S, class View>
COLLIDE_LANE_INLINE void write_velocities(const View& view, BodyIndex i, const BodyLanes<M, S>& body) {
  using T = typename S::value_type;
  T* v[3];
  T* w[3];
  if constexpr (kSoaLayout<View>) {
    v[0] = view.v.x + i, v[1] = view.v.y + i, v[2] = view.v.z + i;
    if constexpr (kRotates<M>) w[0] = view.w.x + i, w[1] = view.w.y + i, w[2] = view.w.z + i;
  } else {
    T* r = reinterpret_cast<T*>(view.bodies + i);
    v[0] = r, v[1] = r + 1, v[2] = r + 2;
    if constexpr (kRotates<M>) w[0] = r + 3, w[1] = r + 4, w[2] = r + 5;
  }
  *v[0] = body.v.x[0], *v[1] = body.v.y[0], *v[2] = body.v.z[0];
  if constexpr (kRotates<M>) *w[0] = body.w.x[0], *w[1] = body.w.y[0], *w[2] = body.w.z[0];
}

/// The geometry of the contacts order[0, count) into `into` (a piece of a
/// run, or the prepared contacts of several passes): what does not depend
/// on the velocities (the offsets, the lever arms and their K terms: most of
/// the arithmetic, and all of the wide lever arms' work), formed in lanes of
/// V, W contacts at a time, the rest one by one. No contact of a solve
/// changes a position or an orientation, so it may be formed before any
/// contact is stepped.
template <class M, class V, class T, class View>
void piece_geometry(const View& bodies, const ContactView<T>& contacts, const std::uint32_t* order, std::size_t count,
                    const GeometryView<T>& into) {
  using S = ScalarLanes<T>;
  constexpr std::size_t W = V::size();
  std::size_t at = 0;
  for (; at + W <= count; at += W) run_geometry<M, V, T>(bodies, contacts, order + at, into, at);
  for (; at < count; ++at) run_geometry<M, S, T>(bodies, contacts, order + at, into, at);
}

/// The walk of the contacts order[0, count), in order, in one lane: each
/// reads the velocities the contacts before it left and takes the law's
/// velocity step (velocity_step) with the geometry piece_geometry formed:
/// the two halves evaluate_law composes, so the bits are those of the
/// one-lane kernel.
template <class M, class T, class View>
void piece_walk(const View& bodies, const ContactView<T>& contacts, const ImpulseView<T>& impulses, bool accumulate,
                const std::uint32_t* order, std::size_t count, const GeometryView<T>& geometry) {
  using S = ScalarLanes<T>;
  for (std::size_t j = 0; j < count; ++j) {
    const std::uint32_t k = order[j];
    const BodyIndex ia = contacts.a[k];
    const BodyIndex ib = contacts.b[k];
    BodyLanes<M, S> a;
    BodyLanes<M, S> b;
    const ContactGeometry<S> g = stored_geometry(geometry, j, a, b);
    read_velocities<M, S>(bodies, ia, a);
    read_velocities<M, S>(bodies, ib, b);
    ContactLanes<S> c;
    c.n = {S(contacts.n.x[k]), S(contacts.n.y[k]), S(contacts.n.z[k])};
    c.e = S(contacts.e != nullptr ? contacts.e[k] : contacts.uniform_e);
    ContactResult<S> r = velocity_step<M, S, false, FastMode>(a, b, c, g);
    canonical_outputs(a, b, r.j);  // as resolve_contacts
    Vec3<S> jv = r.j;
    if (accumulate) jv = summed_impulse(Vec3<S>{S(impulses.j.x[k]), S(impulses.j.y[k]), S(impulses.j.z[k])}, jv);
    if (geometry.inv_mass_a[j] != T(0)) write_velocities<M, S>(bodies, ia, a);
    if (geometry.inv_mass_b[j] != T(0)) write_velocities<M, S>(bodies, ib, b);
    impulses.j.x[k] = jv.x[0];
    impulses.j.y[k] = jv.y[0];
    impulses.j.z[k] = jv.z[0];
  }
}

/// A run of contacts order[begin, end) applied one after another (a chain, a
/// stack: batches of a contact or a few), frictionless, in the fast mode, on
/// this thread: piece after piece, its geometry and then its walk.
template <class M, class V, class T, class View>
void solve_run_pieces(const View& bodies, const ContactView<T>& contacts, const ImpulseView<T>& impulses,
                      bool accumulate, const std::uint32_t* order, std::size_t begin, std::size_t end) {
  RunPiece<T> piece;
  for (std::size_t first = begin; first < end; first += kRunPiece) {
    const std::size_t count = std::min(kRunPiece, end - first);
    piece_geometry<M, V, T>(bodies, contacts, order + first, count, piece.view());
    piece_walk<M, T>(bodies, contacts, impulses, accumulate, order + first, count, piece.view());
  }
}

// ---------------------------------------------------------------------------
// The loops: one named function per choice of the table (kernel_table.hpp),
// never inlined, reached only through the table's pointers.
// ---------------------------------------------------------------------------

/// A loop: never inlined, and everything it calls inlined into it (flatten),
/// but for the calls kept out of line on purpose (noinline:
/// load_streams_out_of_line, evaluate_law_accurately_out_of_line). So what
/// a loop inlines depends on its own source alone; its register allocation
/// and stack slots do not: they move when its unit gains or loses other
/// loops, even with the calls out of line kept from the interprocedural
/// passes (docs/decisions/0052-the-accumulated-passes-in-units-of-their-own.md),
/// which is why a unit's loops stay together. Left to GCC's heuristics,
/// the inlining of what a loop calls beyond the forced inlining of lanes.hpp
/// (libstdc++'s fixed-size simd operators, which the float accurate mode and
/// the rigid float fast mode's double lanes use) depends on a budget for the
/// whole unit (--param inline-unit-growth): in units of a few loops they
/// were called out of line, hundreds of calls in a loop, where the one
/// object of every loop had inlined them all.
#define COLLIDE_KERNEL_LOOP __attribute__((noinline, flatten))

/// The table's index of model M (Model's order: particle, sphere, rigid).
template <class M>
inline constexpr std::size_t kModelSlot = std::is_same_v<M, ParticleModel> ? static_cast<std::size_t>(Model::particle)
                                          : std::is_same_v<M, SphereModel> ? static_cast<std::size_t>(Model::sphere)
                                                                           : static_cast<std::size_t>(Model::rigid);

/// The job's bodies in the view of model M: its SoA view, or with kPacked
/// its packed records (JobBodies' order: the models, then packed). The
/// table chose this loop by that index (job_kernels), so it is the one set.
template <class M, bool kPacked, class T>
COLLIDE_LANE_INLINE const auto& bodies_of(const KernelJob<T>& job) {
  constexpr std::size_t kIndex = kModelSlot<M> + (kPacked ? 3 : 0);
  assert(job.bodies.index() == kIndex);
  // Said to the compiler too, so that no loop tests the index again.
  if (job.bodies.index() != kIndex) __builtin_unreachable();
  return *std::get_if<kIndex>(&job.bodies);
}

/// GroupLoops::solve: the law on groups of V::size() contacts.
template <class M, class V, class Mode, bool kFriction, bool kPacked, class T = typename V::value_type>
COLLIDE_KERNEL_LOOP std::size_t solve_loop(const KernelJob<T>& job, bool contiguous, std::size_t begin,
                                           std::size_t end) {
  assert(job.model() == static_cast<Model>(kModelSlot<M>) && job.packed() == kPacked && job.friction == kFriction &&
         job.accurate == (std::is_same_v<Mode, AccurateMode>)&&!job.stepped);
  return solve_groups<M, V, kFriction, Mode, T>(bodies_of<M, kPacked>(job), job.contacts, job.impulses, job.order,
                                                contiguous, job.accumulate, begin, end);
}

/// GroupLoops::step: the velocity step of the job's contacts [begin, end),
/// consecutive, whose geometry is formed (KernelJob::stepped), in groups of
/// V::size().
template <class M, class V, bool kPacked, class T = typename V::value_type>
COLLIDE_KERNEL_LOOP std::size_t step_loop(const KernelJob<T>& job, [[maybe_unused]] bool contiguous, std::size_t begin,
                                          std::size_t end) {
  // Positions are contact indices: stepped jobs are prepared (identity order).
  assert(job.model() == static_cast<Model>(kModelSlot<M>) && job.packed() == kPacked);
  assert(job.stepped && !job.accurate && !job.friction && (begin == end || job.order[begin] == begin));
  constexpr std::size_t W = V::size();
  const auto& bodies = bodies_of<M, kPacked>(job);
  std::size_t i = begin;
  for (; i + W <= end; i += W) {
    step_group<M, V, T>(bodies, job.contacts, job.impulses, job.geometry, static_cast<std::uint32_t>(i),
                        job.accumulate);
  }
  return i;
}

/// GroupLoops::accumulate: an accumulated pass on groups of V::size()
/// contacts.
template <class M, class V, bool kFriction, bool kPacked, class T = typename V::value_type>
COLLIDE_KERNEL_LOOP std::size_t accumulate_loop(const KernelJob<T>& job, bool contiguous, std::size_t begin,
                                                std::size_t end) {
  assert(job.model() == static_cast<Model>(kModelSlot<M>) && job.packed() == kPacked && job.friction == kFriction);
  assert(job.accumulates() && !job.accurate && !job.stepped && !job.accumulate);
  constexpr std::size_t W = V::size();
  const auto& bodies = bodies_of<M, kPacked>(job);
  std::size_t i = begin;
  for (; i + W <= end; i += W) {
    accumulate_group<M, V, kFriction, T>(bodies, job, ContactGroup{contiguous, job.order[i], job.order + i});
  }
  return i;
}

/// GroupLoops::accumulate_step: an accumulated pass of the job's contacts
/// [begin, end), consecutive, whose geometry is formed (KernelJob::stepped:
/// fast mode, frictionless), in groups of V::size().
template <class M, class V, bool kPacked, class T = typename V::value_type>
COLLIDE_KERNEL_LOOP std::size_t accumulate_step_loop(const KernelJob<T>& job, [[maybe_unused]] bool contiguous,
                                                     std::size_t begin, std::size_t end) {
  assert(job.model() == static_cast<Model>(kModelSlot<M>) && job.packed() == kPacked);
  assert(job.accumulates() && job.stepped && !job.accurate && !job.friction && !job.accumulate);
  assert(begin == end || job.order[begin] == begin);
  constexpr std::size_t W = V::size();
  const auto& bodies = bodies_of<M, kPacked>(job);
  std::size_t i = begin;
  for (; i + W <= end; i += W) accumulate_step_group<M, V, T>(bodies, job, static_cast<std::uint32_t>(i));
  return i;
}

/// KernelLoops::run: a run of the job in pieces (solve_run_pieces), its
/// geometry in the lanes of this ISA.
template <class M, class T, bool kPacked>
COLLIDE_KERNEL_LOOP void run_loop(const KernelJob<T>& job, std::size_t begin, std::size_t end) {
  assert(job.model() == static_cast<Model>(kModelSlot<M>) && job.packed() == kPacked);
  assert(!job.accurate && !job.friction && !job.stepped);
  solve_run_pieces<M, SimdLanes<T>, T>(bodies_of<M, kPacked>(job), job.contacts, job.impulses, job.accumulate,
                                       job.order, begin, end);
}

/// KernelLoops::geometry (RunGeometryKernel of kernel_table.hpp).
template <class M, class T, bool kPacked>
COLLIDE_KERNEL_LOOP void geometry_loop(const KernelJob<T>& job, std::size_t first, std::size_t count,
                                       const GeometryView<T>& into) {
  assert(job.model() == static_cast<Model>(kModelSlot<M>) && job.packed() == kPacked);
  assert(!job.accurate && !job.friction);
  piece_geometry<M, SimdLanes<T>, T>(bodies_of<M, kPacked>(job), job.contacts, job.order + first, count, into);
}

/// KernelLoops::walk (RunWalkKernel of kernel_table.hpp).
template <class M, class T, bool kPacked>
COLLIDE_KERNEL_LOOP void walk_loop(const KernelJob<T>& job, std::size_t first, std::size_t count,
                                   const GeometryView<T>& geometry) {
  assert(job.model() == static_cast<Model>(kModelSlot<M>) && job.packed() == kPacked);
  assert(!job.accurate && !job.friction);
  piece_walk<M, T>(bodies_of<M, kPacked>(job), job.contacts, job.impulses, job.accumulate, job.order + first, count,
                   geometry);
}

/// Model M's solve slots of `loops` in mode Mode, in lanes V (an ISA's, or
/// one lane): with and without friction, on both layouts.
template <class M, class V, class Mode>
void add_solve_loops(GroupLoops<typename V::value_type>& loops) {
  auto& slots = loops.solve[kModelSlot<M>][std::is_same_v<Mode, AccurateMode> ? 1 : 0];
  slots[0][0] = &solve_loop<M, V, Mode, false, false>;
  slots[0][1] = &solve_loop<M, V, Mode, false, true>;
  slots[1][0] = &solve_loop<M, V, Mode, true, false>;
  slots[1][1] = &solve_loop<M, V, Mode, true, true>;
}

/// Model M's accumulated-pass slots of `loops`, in lanes V: with and without
/// friction, on both layouts.
template <class M, class V>
void add_accumulate_loops(GroupLoops<typename V::value_type>& loops) {
  auto& slots = loops.accumulate[kModelSlot<M>];
  slots[0][0] = &accumulate_loop<M, V, false, false>;
  slots[0][1] = &accumulate_loop<M, V, false, true>;
  slots[1][0] = &accumulate_loop<M, V, true, false>;
  slots[1][1] = &accumulate_loop<M, V, true, true>;
  loops.accumulate_step[kModelSlot<M>][0] = &accumulate_step_loop<M, V, false>;
  loops.accumulate_step[kModelSlot<M>][1] = &accumulate_step_loop<M, V, true>;
}

/// Model M's velocity-step slots of `loops`, in lanes V, on both layouts.
template <class M, class V>
void add_step_loops(GroupLoops<typename V::value_type>& loops) {
  loops.step[kModelSlot<M>][0] = &step_loop<M, V, false>;
  loops.step[kModelSlot<M>][1] = &step_loop<M, V, true>;
}

/// The slots of one kernel unit in the lanes of this ISA's table: model M's
/// loops of precision T in mode Mode; the fast mode's unit also holds the loops
/// that only the fast mode has (the velocity step and the run's).
template <class M, class T, class Mode>
void add_unit_loops(KernelTable& table) {
  KernelLoops<T>& loops = *of_precision<T>(&table.loops_float, &table.loops_double);
  add_solve_loops<M, SimdLanes<T>, Mode>(loops.groups);
  if constexpr (std::is_same_v<Mode, FastMode>) {
    constexpr std::size_t m = kModelSlot<M>;
    add_step_loops<M, SimdLanes<T>>(loops.groups);
    add_accumulate_loops<M, SimdLanes<T>>(loops.groups);
    loops.run[m][0] = &run_loop<M, T, false>;
    loops.run[m][1] = &run_loop<M, T, true>;
    loops.geometry[m][0] = &geometry_loop<M, T, false>;
    loops.geometry[m][1] = &geometry_loop<M, T, true>;
    loops.walk[m][0] = &walk_loop<M, T, false>;
    loops.walk[m][1] = &walk_loop<M, T, true>;
  }
}

/// Model M's one-lane slots of `loops`: both modes, both layouts.
template <class M, class T>
void add_one_lane_loops(GroupLoops<T>& loops) {
  add_solve_loops<M, ScalarLanes<T>, FastMode>(loops);
  add_solve_loops<M, ScalarLanes<T>, AccurateMode>(loops);
  add_step_loops<M, ScalarLanes<T>>(loops);
  add_accumulate_loops<M, ScalarLanes<T>>(loops);
}

}  // namespace
}  // namespace COLLIDE_KERNEL_NS
}  // namespace collide::detail
