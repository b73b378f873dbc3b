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
/// (transpose_lanes.hpp): the record's values in its own order, each put in
/// the lane of its field (the model's table, collide/bodies.hpp); a rigid
/// body's inverse mass, kept beside the records, by lanes from the view's
/// dense array.
template <class M, class V, class Record, class Index>
COLLIDE_LANE_INLINE void read_records(const PackedView<Record>& view, const Index* idx, BodyLanes<M, V>& body) {
  using T = typename V::value_type;
  constexpr std::size_t N = kRecordValues<Record>;
  const T* base = reinterpret_cast<const T*>(view.bodies);
  V x[N];
  load_record_values<V, N, kStride<Record>>(base, idx, x);
  for_each_lane_field<Record>([&](auto at) COLLIDE_LANE_LAMBDA {
    using At = decltype(at);
    if constexpr (!kKeptBeside<Record, At::field.member>) {
      static_assert(record_slot<Record, At>() < N);
      At::of(body) = x[record_slot<Record, At>()];
    }
  });
  if constexpr (std::is_same_v<M, RigidModel>) {
    body.rotation = normalised_rotation(body.q);
    // The one field kept beside the records (kKeptBeside), after their rows.
    body.inv_mass = gather<V>(static_cast<const T*>(view.inv_mass), idx);
  }
}

/// Writes v (and w) of the lanes in `write` back into their records: the
/// values the kernel changes (ArrayRole::velocity), the first of each record.
template <class M, class V, class Record, class Index>
COLLIDE_LANE_INLINE void write_records(const PackedView<Record>& view, const Index* idx, const BodyLanes<M, V>& body,
                                       const typename V::mask_type& write) {
  using T = typename V::value_type;
  constexpr std::size_t N = kRotates<M> ? 6 : 3;
  T* base = reinterpret_cast<T*>(view.bodies);
  V x[N];
  for_each_lane_field<Record>([&](auto at) COLLIDE_LANE_LAMBDA {
    using At = decltype(at);
    if constexpr (At::field.role == ArrayRole::velocity) {
      static_assert(record_slot<Record, At>() < N, "the velocities lead the record");
      x[record_slot<Record, At>()] = At::of(body);
    }
  });
  store_record_values<V, N, kStride<Record>>(base, idx, x, write);
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
