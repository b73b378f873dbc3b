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

/// A 3-vector of arrays, element i, into a record's three values and back.
template <class T, class U>
void get3(T (&to)[3], const Vec3Array<U>& from, std::size_t i) {
  to[0] = from.x[i], to[1] = from.y[i], to[2] = from.z[i];
}
template <class T>
void put3(const Vec3Array<T>& to, const T (&from)[3], std::size_t i) {
  to.x[i] = from[0], to.y[i] = from[1], to.z[i] = from[2];
}

/// v (and w where the record has it) of the movable bodies, back into SoA.
template <class Record, class View>
void unpack_velocities_of(const PackedView<Record>& from, const View& to) {
  using T = typename PackedValue<Record>::type;
  check_counts(from.count, to.count, "collide::unpack_velocities");
  for_bodies(from.count, [&](std::size_t i) {
    const Record& r = from.bodies[i];
    if (packed_inv_mass(from, i) == T(0)) return;
    put3(to.v, r.v, i);
    if constexpr (!std::is_same_v<Record, PackedParticle<T>>) put3(to.w, r.w, i);
  });
}

}  // namespace

template <class U>
void pack(const BodyView<U>& from, const PackedView<PackedRigid<std::remove_const_t<U>>>& to) {
  check_counts(from.count, to.count, "collide::pack");
  for_bodies(from.count, [&](std::size_t i) {
    auto& r = to.bodies[i];
    get3(r.v, from.v, i), get3(r.w, from.w, i), get3(r.p, from.p, i);
    r.q[0] = from.q.w[i], r.q[1] = from.q.x[i], r.q[2] = from.q.y[i], r.q[3] = from.q.z[i];
    // The solver packs SoA input with the caller's inverse masses as the
    // view's own: nothing to copy then.
    if (to.inv_mass != from.inv_mass) to.inv_mass[i] = from.inv_mass[i];
    r.inv_inertia[0] = from.inv_inertia.x[i], r.inv_inertia[1] = from.inv_inertia.y[i];
    r.inv_inertia[2] = from.inv_inertia.z[i];
  });
}

template <class U>
void pack(const SphereView<U>& from, const PackedView<PackedSphere<std::remove_const_t<U>>>& to) {
  check_counts(from.count, to.count, "collide::pack");
  for_bodies(from.count, [&](std::size_t i) {
    auto& r = to.bodies[i];
    get3(r.v, from.v, i), get3(r.w, from.w, i), get3(r.p, from.p, i);
    r.inv_mass = from.inv_mass[i];
    r.inv_inertia = from.inv_inertia[i];
  });
}

template <class U>
void pack(const ParticleView<U>& from, const PackedView<PackedParticle<std::remove_const_t<U>>>& to) {
  check_counts(from.count, to.count, "collide::pack");
  for_bodies(from.count, [&](std::size_t i) {
    auto& r = to.bodies[i];
    get3(r.v, from.v, i);
    r.inv_mass = from.inv_mass[i];
  });
}

template <class T>
void unpack(const PackedView<PackedRigid<T>>& from, const BodyView<T>& to) {
  check_counts(from.count, to.count, "collide::unpack");
  for_bodies(from.count, [&](std::size_t i) {
    const auto& r = from.bodies[i];
    put3(to.v, r.v, i), put3(to.w, r.w, i), put3(to.p, r.p, i);
    to.q.w[i] = r.q[0], to.q.x[i] = r.q[1], to.q.y[i] = r.q[2], to.q.z[i] = r.q[3];
    to.inv_mass[i] = from.inv_mass[i];
    to.inv_inertia.x[i] = r.inv_inertia[0], to.inv_inertia.y[i] = r.inv_inertia[1];
    to.inv_inertia.z[i] = r.inv_inertia[2];
  });
}

template <class T>
void unpack(const PackedView<PackedSphere<T>>& from, const SphereView<T>& to) {
  check_counts(from.count, to.count, "collide::unpack");
  for_bodies(from.count, [&](std::size_t i) {
    const auto& r = from.bodies[i];
    put3(to.v, r.v, i), put3(to.w, r.w, i), put3(to.p, r.p, i);
    to.inv_mass[i] = r.inv_mass;
    to.inv_inertia[i] = r.inv_inertia;
  });
}

template <class T>
void unpack(const PackedView<PackedParticle<T>>& from, const ParticleView<T>& to) {
  check_counts(from.count, to.count, "collide::unpack");
  for_bodies(from.count, [&](std::size_t i) {
    const auto& r = from.bodies[i];
    put3(to.v, r.v, i);
    to.inv_mass[i] = r.inv_mass;
  });
}

template <class T>
void unpack_velocities(const PackedView<PackedRigid<T>>& from, const BodyView<T>& to) {
  unpack_velocities_of(from, to);
}

template <class T>
void unpack_velocities(const PackedView<PackedSphere<T>>& from, const SphereView<T>& to) {
  unpack_velocities_of(from, to);
}

template <class T>
void unpack_velocities(const PackedView<PackedParticle<T>>& from, const ParticleView<T>& to) {
  unpack_velocities_of(from, to);
}

template void pack<float>(const BodyView<float>&, const PackedView<PackedRigid<float>>&);
template void pack<float>(const SphereView<float>&, const PackedView<PackedSphere<float>>&);
template void pack<float>(const ParticleView<float>&, const PackedView<PackedParticle<float>>&);
template void pack<const float>(const BodyView<const float>&, const PackedView<PackedRigid<float>>&);
template void pack<const float>(const SphereView<const float>&, const PackedView<PackedSphere<float>>&);
template void pack<const float>(const ParticleView<const float>&, const PackedView<PackedParticle<float>>&);
template void pack<double>(const BodyView<double>&, const PackedView<PackedRigid<double>>&);
template void pack<double>(const SphereView<double>&, const PackedView<PackedSphere<double>>&);
template void pack<double>(const ParticleView<double>&, const PackedView<PackedParticle<double>>&);
template void pack<const double>(const BodyView<const double>&, const PackedView<PackedRigid<double>>&);
template void pack<const double>(const SphereView<const double>&, const PackedView<PackedSphere<double>>&);
template void pack<const double>(const ParticleView<const double>&, const PackedView<PackedParticle<double>>&);
template void unpack<float>(const PackedView<PackedRigid<float>>&, const BodyView<float>&);
template void unpack<float>(const PackedView<PackedSphere<float>>&, const SphereView<float>&);
template void unpack<float>(const PackedView<PackedParticle<float>>&, const ParticleView<float>&);
template void unpack_velocities<float>(const PackedView<PackedRigid<float>>&, const BodyView<float>&);
template void unpack_velocities<float>(const PackedView<PackedSphere<float>>&, const SphereView<float>&);
template void unpack_velocities<float>(const PackedView<PackedParticle<float>>&, const ParticleView<float>&);
template void unpack<double>(const PackedView<PackedRigid<double>>&, const BodyView<double>&);
template void unpack<double>(const PackedView<PackedSphere<double>>&, const SphereView<double>&);
template void unpack<double>(const PackedView<PackedParticle<double>>&, const ParticleView<double>&);
template void unpack_velocities<double>(const PackedView<PackedRigid<double>>&, const BodyView<double>&);
template void unpack_velocities<double>(const PackedView<PackedSphere<double>>&, const SphereView<double>&);
template void unpack_velocities<double>(const PackedView<PackedParticle<double>>&, const ParticleView<double>&);

}  // namespace collide
