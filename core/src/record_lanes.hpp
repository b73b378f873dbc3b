// record_lanes.hpp - the bodies of W contacts moved between packed records
// (collide/packed.hpp) and lanes: read_records fills BodyLanes from the
// records by row loads and register transposes (transpose_lanes.hpp), and a
// rigid body's inverse mass by lanes from the view's dense array;
// write_records puts v and w back, prefetch_record asks for a record's lines
// ahead of use. The value order of each record is asserted here, where the
// transposes depend on it.
#pragma once

#include <cstddef>
#include <type_traits>

#include "collide/packed.hpp"
#include "contact_kernel.hpp"
#include "lanes.hpp"
#include "transpose_lanes.hpp"

namespace collide::detail {
inline namespace COLLIDE_KERNEL_NS {

/// Values of one record: the stride, in values, from record i to record i + 1.
template <class Record>
inline constexpr std::size_t kStride = sizeof(Record) / sizeof(typename PackedValue<Record>::type);

/// The W bodies idx[0..W) of a packed layout, read into lanes row by row
/// (transpose_lanes.hpp). The value order is the record's (collide/packed.hpp).
template <class M, class V, class Record, class Index>
COLLIDE_LANE_INLINE void read_records(const PackedView<Record>& view, const Index* idx, BodyLanes<M, V>& body) {
  using T = typename V::value_type;
  constexpr std::size_t S = kStride<Record>;
  const T* base = reinterpret_cast<const T*>(view.bodies);
  if constexpr (std::is_same_v<Record, PackedRigid<T>>) {
    static_assert(offsetof(PackedRigid<T>, inv_inertia) == 13 * sizeof(T) && S == 16, "value order of PackedRigid");
    V x[16];
    load_record_values<V, 16, S>(base, idx, x);
    body.v = {x[0], x[1], x[2]};
    body.w = {x[3], x[4], x[5]};
    body.p = {x[6], x[7], x[8]};
    body.q = {x[9], x[10], x[11], x[12]};
    body.rotation = normalised_rotation(body.q);
    body.inv_inertia = {x[13], x[14], x[15]};
    body.inv_mass = gather<V>(static_cast<const T*>(view.inv_mass), idx);
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
COLLIDE_LANE_INLINE void write_records(const PackedView<Record>& view, const Index* idx, const BodyLanes<M, V>& body,
                                       const typename V::mask_type& write) {
  using T = typename V::value_type;
  constexpr std::size_t S = kStride<Record>;
  T* base = reinterpret_cast<T*>(view.bodies);
  if constexpr (kRotates<M>) {
    const V x[6] = {body.v.x, body.v.y, body.v.z, body.w.x, body.w.y, body.w.z};
    store_record_values<V, 6, S>(base, idx, x, write);
  } else {
    const V x[3] = {body.v.x, body.v.y, body.v.z};
    store_record_values<V, 3, S>(base, idx, x, write);
  }
}

/// Asks for the cache lines of body i's record (and of a rigid body's
/// inverse mass) ahead of use.
template <class Record>
COLLIDE_LANE_INLINE void prefetch_record(const PackedView<Record>& view, std::size_t i) {
  const char* first = reinterpret_cast<const char*>(view.bodies + i);
  for (std::size_t offset = 0; offset < sizeof(Record); offset += 64) __builtin_prefetch(first + offset, 0, 2);
  using T = typename PackedValue<Record>::type;
  if constexpr (std::is_same_v<Record, PackedRigid<T>>) __builtin_prefetch(view.inv_mass + i, 0, 2);
}

}  // namespace COLLIDE_KERNEL_NS
}  // namespace collide::detail
