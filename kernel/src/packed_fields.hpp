// packed_fields.hpp - the packed records (collide/packed.hpp) seen through the
// member names of the SoA views, so that the kernel's field lists
// (kernel_isa.cpp: read_bodies, write_bodies) serve both layouts unchanged.
//
// A field of a packed layout is a StridedField: the address of the field in
// record 0 and the record size as a compile-time stride, so body i's value is
// base[i * S]. gather/scatter below are the lane fills for it: one load per
// lane, from the one or two cache lines of each record.
#pragma once

#include <cstddef>
#include <type_traits>

#include "collide/packed.hpp"
#include "contact_kernel.hpp"
#include "lanes.hpp"
#include "transpose_lanes.hpp"

namespace collide::detail {
inline namespace COLLIDE_KERNEL_NS {

template <class T, std::size_t S>
struct StridedField {
  T* base;
};

template <class T, std::size_t S>
struct StridedVec3 {
  StridedField<T, S> x, y, z;
};

template <class T, std::size_t S>
struct StridedQuat {
  StridedField<T, S> w, x, y, z;
};

template <class Record>
inline constexpr std::size_t kStride = sizeof(Record) / sizeof(typename PackedValue<Record>::type);

/// The field views of each packed record type: the members a model's field
/// list names.
template <class Record>
struct PackedFields;

template <class T>
struct PackedFields<PackedRigid<T>> {
  static constexpr std::size_t S = kStride<PackedRigid<T>>;
  std::size_t count;
  StridedField<T, S> inv_mass;
  StridedVec3<T, S> inv_inertia;
  StridedQuat<T, S> q;
  StridedVec3<T, S> p, v, w;
  explicit PackedFields(const PackedView<PackedRigid<T>>& view)
      : count(view.count),
        inv_mass{&view.bodies->inv_mass},
        inv_inertia{{&view.bodies->inv_inertia[0]}, {&view.bodies->inv_inertia[1]}, {&view.bodies->inv_inertia[2]}},
        q{{&view.bodies->q[0]}, {&view.bodies->q[1]}, {&view.bodies->q[2]}, {&view.bodies->q[3]}},
        p{{&view.bodies->p[0]}, {&view.bodies->p[1]}, {&view.bodies->p[2]}},
        v{{&view.bodies->v[0]}, {&view.bodies->v[1]}, {&view.bodies->v[2]}},
        w{{&view.bodies->w[0]}, {&view.bodies->w[1]}, {&view.bodies->w[2]}} {}
};

template <class T>
struct PackedFields<PackedSphere<T>> {
  static constexpr std::size_t S = kStride<PackedSphere<T>>;
  std::size_t count;
  StridedField<T, S> inv_mass;
  StridedField<T, S> inv_inertia;
  StridedVec3<T, S> p, v, w;
  explicit PackedFields(const PackedView<PackedSphere<T>>& view)
      : count(view.count),
        inv_mass{&view.bodies->inv_mass},
        inv_inertia{&view.bodies->inv_inertia},
        p{{&view.bodies->p[0]}, {&view.bodies->p[1]}, {&view.bodies->p[2]}},
        v{{&view.bodies->v[0]}, {&view.bodies->v[1]}, {&view.bodies->v[2]}},
        w{{&view.bodies->w[0]}, {&view.bodies->w[1]}, {&view.bodies->w[2]}} {}
};

template <class T>
struct PackedFields<PackedParticle<T>> {
  static constexpr std::size_t S = kStride<PackedParticle<T>>;
  std::size_t count;
  StridedField<T, S> inv_mass;
  StridedVec3<T, S> v;
  explicit PackedFields(const PackedView<PackedParticle<T>>& view)
      : count(view.count),
        inv_mass{&view.bodies->inv_mass},
        v{{&view.bodies->v[0]}, {&view.bodies->v[1]}, {&view.bodies->v[2]}} {}
};

/// base[idx[0] * S], ..., base[idx[W-1] * S].
template <class V, class T, std::size_t S, class Index>
COLLIDE_LANE_INLINE V gather(const StridedField<T, S>& field, const Index* idx) {
  return V([&](auto lane) { return field.base[static_cast<std::size_t>(idx[lane]) * S]; });
}

/// base[idx[l] * S] = v[l] for every lane l whose `write` is true.
template <class V, class T, std::size_t S, class Index>
COLLIDE_LANE_INLINE void scatter(const V& v, const StridedField<T, S>& field, const Index* idx,
                                 const typename V::mask_type& write) {
  for (std::size_t l = 0; l < V::size(); ++l) {
    if (write[l]) field.base[static_cast<std::size_t>(idx[l]) * S] = v[l];
  }
}

/// The W bodies idx[0..W) of a packed layout, read into lanes row by row
/// (transpose_lanes.hpp). The value order is the record's (collide/packed.hpp).
template <class M, class V, class Record, class Index>
COLLIDE_LANE_INLINE void read_records(const Record* records, const Index* idx, BodyLanes<M, V>& body) {
  using T = typename V::value_type;
  constexpr std::size_t S = kStride<Record>;
  const T* base = reinterpret_cast<const T*>(records);
  if constexpr (std::is_same_v<Record, PackedRigid<T>>) {
    static_assert(offsetof(PackedRigid<T>, inv_inertia) == 14 * sizeof(T), "value order of PackedRigid");
    V x[17];
    load_record_values<V, 17, S>(base, idx, x);
    body.v = {x[0], x[1], x[2]};
    body.w = {x[3], x[4], x[5]};
    body.p = {x[6], x[7], x[8]};
    body.q = {x[9], x[10], x[11], x[12]};
    body.rotation = rotation(x[9], x[10], x[11], x[12]);
    body.inv_mass = x[13];
    body.inv_inertia = {x[14], x[15], x[16]};
  } else if constexpr (std::is_same_v<Record, PackedSphere<T>>) {
    static_assert(offsetof(PackedSphere<T>, inv_inertia) == 10 * sizeof(T), "value order of PackedSphere");
    V x[11];
    load_record_values<V, 11, S>(base, idx, x);
    body.v = {x[0], x[1], x[2]};
    body.w = {x[3], x[4], x[5]};
    body.p = {x[6], x[7], x[8]};
    body.inv_mass = x[9];
    body.inv_inertia.x = x[10];
  } else {
    static_assert(offsetof(PackedParticle<T>, inv_mass) == 3 * sizeof(T), "value order of PackedParticle");
    V x[4];
    load_record_values<V, 4, S>(base, idx, x);
    body.v = {x[0], x[1], x[2]};
    body.inv_mass = x[3];
  }
}

/// Writes v (and w) of the lanes in `write` back into their records: the
/// values the kernel changes, the first of each record.
template <class M, class V, class Record, class Index>
COLLIDE_LANE_INLINE void write_records(Record* records, const Index* idx, const BodyLanes<M, V>& body,
                                       const typename V::mask_type& write) {
  using T = typename V::value_type;
  constexpr std::size_t S = kStride<Record>;
  T* base = reinterpret_cast<T*>(records);
  if constexpr (kRotates<M>) {
    const V x[6] = {body.v.x, body.v.y, body.v.z, body.w.x, body.w.y, body.w.z};
    store_record_values<V, 6, S>(base, idx, x, write);
  } else {
    const V x[3] = {body.v.x, body.v.y, body.v.z};
    store_record_values<V, 3, S>(base, idx, x, write);
  }
}

/// Asks for the cache lines of record i (first and last byte) ahead of use.
template <class Record>
COLLIDE_LANE_INLINE void prefetch_record(const Record* records, std::size_t i) {
  const char* first = reinterpret_cast<const char*>(records + i);
  for (std::size_t offset = 0; offset < sizeof(Record); offset += 64) __builtin_prefetch(first + offset, 0, 2);
}

}  // namespace COLLIDE_KERNEL_NS
}  // namespace collide::detail
