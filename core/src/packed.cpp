// packed.cpp - exact conversions between the SoA views and the packed layout
// (collide/packed.hpp). Plain copies, one body at a time, blocks of bodies in
// parallel: each body is read and written by one task, so the result does not
// depend on the thread count.
#include "collide/packed.hpp"

#include <cstddef>
#include <stdexcept>
#include <string>

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>

namespace collide {
namespace {

/// Bodies per task: a few hundred KiB of records, far above TBB's task cost.
constexpr std::size_t kGrain = 8192;

void check_counts(std::size_t from, std::size_t to, const char* what) {
  if (from != to) {
    throw std::invalid_argument(std::string(what) + ": the views hold " + std::to_string(from) + " and " +
                                std::to_string(to) + " bodies");
  }
}

template <class F>
void for_bodies(std::size_t count, F&& f) {
  if (count <= kGrain) {
    for (std::size_t i = 0; i < count; ++i) f(i);
    return;
  }
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, kGrain), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i) f(i);
  });
}

}  // namespace

// Every field of the model's table (collide/bodies.hpp), body by body. A
// rigid view's inverse masses, kept beside the records, are copied between
// the two arrays, unless they are one (the solver packs SoA input that way).
template <class View>
void pack(const View& from, const PackedView<typename RecordOf<View>::type>& to) {
  using Record = typename RecordOf<View>::type;
  using T = typename PackedValue<Record>::type;
  check_counts(from.count, to.count, "collide::pack");
  for_bodies(from.count, [&](std::size_t i) {
    Record& r = to.bodies[i];
    for_each_body_field<Record>([&](auto at) {
      using At = decltype(at);
      if constexpr (kKeptBeside<Record, At::field.member>) {
        T* beside = beside_records(to);
        if (beside != At::of(from)) beside[i] = At::of(from)[i];
      } else {
        At::of(r) = At::of(from)[i];
      }
    });
  });
}

namespace {

/// Every field of the model's table (collide/bodies.hpp) back, body by body;
/// with kVelocitiesOnly, only v and w of the movable bodies. A rigid view's
/// inverse masses, kept beside the records, come from the view's array.
template <bool kVelocitiesOnly, class Record, class View>
void unpack_fields(const PackedView<Record>& from, const View& to) {
  using T = typename PackedValue<Record>::type;
  check_counts(from.count, to.count, kVelocitiesOnly ? "collide::unpack_velocities" : "collide::unpack");
  for_bodies(from.count, [&](std::size_t i) {
    const Record& r = from.bodies[i];
    if (kVelocitiesOnly && packed_inv_mass(from, i) == T(0)) return;
    for_each_body_field<Record>([&](auto at) {
      using At = decltype(at);
      if constexpr (kVelocitiesOnly && At::field.role != ArrayRole::velocity) {
        return;
      } else if constexpr (kKeptBeside<Record, At::field.member>) {
        At::of(to)[i] = beside_records(from)[i];
      } else {
        At::of(to)[i] = At::of(r);
      }
    });
  });
}

}  // namespace

template <class Record>
void unpack(const PackedView<Record>& from, const typename SoaViewOf<Record>::type& to) {
  unpack_fields<false>(from, to);
}

template <class Record>
void unpack_velocities(const PackedView<Record>& from, const typename SoaViewOf<Record>::type& to) {
  unpack_fields<true>(from, to);
}

// The conversions of every model, for T and const T input (T is a type:
// no parentheses).
// NOLINTBEGIN(bugprone-macro-parentheses)
#define COLLIDE_INSTANTIATE(T)                                                                                   \
  template void pack<BodyView<T>>(const BodyView<T>&, const PackedView<PackedRigid<T>>&);                        \
  template void pack<BodyView<const T>>(const BodyView<const T>&, const PackedView<PackedRigid<T>>&);            \
  template void unpack<PackedRigid<T>>(const PackedView<PackedRigid<T>>&, const BodyView<T>&);                   \
  template void unpack_velocities<PackedRigid<T>>(const PackedView<PackedRigid<T>>&, const BodyView<T>&);        \
  template void pack<SphereView<T>>(const SphereView<T>&, const PackedView<PackedSphere<T>>&);                   \
  template void pack<SphereView<const T>>(const SphereView<const T>&, const PackedView<PackedSphere<T>>&);       \
  template void unpack<PackedSphere<T>>(const PackedView<PackedSphere<T>>&, const SphereView<T>&);               \
  template void unpack_velocities<PackedSphere<T>>(const PackedView<PackedSphere<T>>&, const SphereView<T>&);    \
  template void pack<ParticleView<T>>(const ParticleView<T>&, const PackedView<PackedParticle<T>>&);             \
  template void pack<ParticleView<const T>>(const ParticleView<const T>&, const PackedView<PackedParticle<T>>&); \
  template void unpack<PackedParticle<T>>(const PackedView<PackedParticle<T>>&, const ParticleView<T>&);         \
  template void unpack_velocities<PackedParticle<T>>(const PackedView<PackedParticle<T>>&, const ParticleView<T>&);
COLLIDE_INSTANTIATE(float)
COLLIDE_INSTANTIATE(double)
#undef COLLIDE_INSTANTIATE
// NOLINTEND(bugprone-macro-parentheses)

}  // namespace collide
