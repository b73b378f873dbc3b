// isa_calibration.cpp - the measurement behind collide::fastest_isa (the
// design notes are in isa_calibration.hpp).
#include "isa_calibration.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <mutex>
#include <numeric>
#include <utility>
#include <vector>

#include "collide/bodies.hpp"
#include "collide/contacts.hpp"
#include "collide/packed.hpp"
#include "kernel_table.hpp"

namespace collide {
namespace detail {
namespace {

using Clock = std::chrono::steady_clock;

/// Contacts of the synthetic scene: a multiple of every lane width, so no
/// pass has a scalar tail, and small enough for L2 in double (rigid: ~280
/// KiB of bodies and ~90 KiB of contacts).
constexpr std::size_t kContacts = 1024;
/// Contacts of a warm-up pass, which also estimates each ISA's cost per
/// contact; and the fewest a timed pass runs.
constexpr std::size_t kWarmUpContacts = 256;
/// A timed pass runs as many contacts (a multiple of kGroup, at most
/// kContacts) as the slowest ISA resolves in about this time: the slow
/// kernels (double, accurate mode, on SSE2) would otherwise make a key cost
/// many times the fast ones' (docs/decisions/0006-run-time-instruction-set-choice.md has their costs).
constexpr double kPassSeconds = 100e-6;
constexpr std::size_t kGroup = 64;
/// Timed rounds, after one warm-up round.
constexpr int kRounds = 5;

constexpr Isa kIsas[] = {Isa::sse2, Isa::avx2, Isa::avx512};

int isa_index(Isa isa) { return static_cast<int>(isa) - static_cast<int>(Isa::sse2); }

/// splitmix64: plausible values for the scene, the same in every process.
class Draw {
 public:
  explicit Draw(std::uint64_t seed) : state_(seed) {}
  std::uint64_t next() {
    std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
  }
  double uniform(double lo, double hi) { return lo + (hi - lo) * static_cast<double>(next() >> 11) * 0x1.0p-53; }
  std::size_t below(std::size_t n) { return static_cast<std::size_t>(next() % n); }

 private:
  std::uint64_t state_;
};

/// The synthetic scene of one key, and the KernelJob that runs it.
template <class T>
class CalibrationScene {
 public:
  CalibrationScene(Model model, Accuracy accuracy, bool scattered) : scattered_(scattered) {
    Draw draw(scattered ? 0x5CA77E4ED : 0x57EA4141);
    // Bodies: streaming 2k and 2k + 1 per contact k; scattered, the same
    // count shuffled, plus the immovable ground as the last body.
    const std::size_t movable = 2 * kContacts;
    const std::size_t count = movable + (scattered ? 1 : 0);
    std::vector<BodyIndex> slots(movable);
    std::iota(slots.begin(), slots.end(), BodyIndex{0});
    if (scattered) {
      for (std::size_t i = movable - 1; i > 0; --i) std::swap(slots[i], slots[draw.below(i + 1)]);
    }
    std::vector<BodyRecord<T>> records(count);
    for (BodyRecord<T>& r : records) {
      r.m = static_cast<T>(draw.uniform(0.5, 2.0));
      for (T& i : r.I) i = static_cast<T>(draw.uniform(0.2, 2.0));
      for (T& q : r.q) q = static_cast<T>(draw.uniform(-1.0, 1.0));
      r.q[0] = static_cast<T>(r.q[0] + T(2));  // |q| well away from 0
      for (T& w : r.w) w = static_cast<T>(draw.uniform(-1.0, 1.0));
    }
    const BodyIndex ground = static_cast<BodyIndex>(movable);
    if (scattered) {
      BodyRecord<T>& g = records[ground];
      g.m = std::numeric_limits<T>::infinity();
      for (T& i : g.I) i = std::numeric_limits<T>::infinity();
      for (T& w : g.w) w = T(0);
    }

    // Contacts: unit normal n from b towards a, the bodies a unit apart
    // along it and approaching.
    for (std::size_t k = 0; k < kContacts; ++k) {
      ContactRecord<T> c;
      c.a = slots[2 * k];
      c.b = scattered && k % 4 == 3 ? ground : slots[2 * k + 1];
      double n[3] = {draw.uniform(-1, 1), draw.uniform(-1, 1), draw.uniform(0.5, 1)};
      const double norm = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
      for (int d = 0; d < 3; ++d) {
        n[d] /= norm;
        const double centre = draw.uniform(-10, 10);
        c.c[d] = static_cast<T>(centre);
        c.n[d] = static_cast<T>(n[d]);
        records[c.a].p[d] = static_cast<T>(centre + 0.5 * n[d]);
        records[c.a].v[d] = static_cast<T>(-n[d] + draw.uniform(-0.2, 0.2));
        if (c.b != ground) {
          records[c.b].p[d] = static_cast<T>(centre - 0.5 * n[d]);
          records[c.b].v[d] = static_cast<T>(n[d] + draw.uniform(-0.2, 0.2));
        }
      }
      c.e = static_cast<T>(draw.uniform(0, 1));
      c.mu = T(0);  // frictionless: view() leaves mu out
      contacts_.push_back(c);
    }
    for (const BodyRecord<T>& r : records) bodies_.push_back(r);
    impulses_.resize(kContacts);

    // The order: the contacts in sequence (streaming, read as vectors) or
    // shuffled (scattered, gathered through the order).
    order_.resize(kContacts);
    std::iota(order_.begin(), order_.end(), std::uint32_t{0});
    if (scattered) {
      for (std::size_t i = kContacts - 1; i > 0; --i) std::swap(order_[i], order_[draw.below(i + 1)]);
    }

    job_.accurate = accuracy == Accuracy::accurate;
    job_.friction = false;
    job_.contacts = contacts_.view();
    job_.impulses = impulses_.view();
    job_.order = order_.data();
    const BodyView<T> soa = bodies_.view();
    // The SoA view of the model, or records packed from it for a scattered scene.
    const auto use = [&](const auto& view, auto& records) {
      if (scattered) {
        records.resize(count);
        const auto packed = packed_view(records);
        pack(view, packed);
        job_.bodies = packed;
      } else {
        job_.bodies = view;
      }
    };
    switch (model) {
      case Model::particle:
        use(particle_view(soa), particle_records_);
        break;
      case Model::sphere:
        use(sphere_view(soa), sphere_records_);
        break;
      case Model::rigid:
        use(soa, rigid_records_);
        break;
    }
    saved_bodies_ = bodies_;
    saved_particle_ = particle_records_;
    saved_sphere_ = sphere_records_;
    saved_rigid_ = rigid_records_;
  }
  CalibrationScene(const CalibrationScene&) = delete;
  CalibrationScene& operator=(const CalibrationScene&) = delete;

  /// The state every pass starts from (copies into the same storage: the
  /// views stay valid).
  void restore() {
    if (!scattered_) {
      const BodyView<T> to = bodies_.view();
      const BodyView<const T> from = std::as_const(saved_bodies_).view();
      const std::size_t n = to.count;
      for (const auto& [dst, src] : {std::pair{to.v, from.v}, std::pair{to.w, from.w}}) {
        std::copy_n(src.x, n, dst.x);
        std::copy_n(src.y, n, dst.y);
        std::copy_n(src.z, n, dst.z);
      }
      return;
    }
    std::copy(saved_particle_.bodies.begin(), saved_particle_.bodies.end(), particle_records_.bodies.begin());
    std::copy(saved_sphere_.bodies.begin(), saved_sphere_.bodies.end(), sphere_records_.bodies.begin());
    std::copy(saved_rigid_.bodies.begin(), saved_rigid_.bodies.end(), rigid_records_.bodies.begin());
  }

  /// One pass of the SIMD loops of `table` over the first `contacts` of the
  /// order; returns its wall time [s].
  double pass(const KernelTable& table, std::size_t contacts) {
    const JobKernels<T> kernels = job_kernels(table, job_, true);
    restore();
    const auto t0 = Clock::now();
    kernels.range(job_, !scattered_, 0, contacts);
    return std::chrono::duration<double>(Clock::now() - t0).count();
  }

 private:
  bool scattered_;
  BodyBuffer<T> bodies_, saved_bodies_;
  ContactBuffer<T> contacts_;
  ImpulseBuffer<T> impulses_;
  std::vector<std::uint32_t> order_;
  PackedBuffer<PackedParticle<T>> particle_records_, saved_particle_;
  PackedBuffer<PackedSphere<T>> sphere_records_, saved_sphere_;
  PackedBuffer<PackedRigid<T>> rigid_records_, saved_rigid_;
  KernelJob<T> job_;
};

template <class T>
IsaMeasurement measure(Model model, Accuracy accuracy, bool scattered) {
  const auto start = Clock::now();
  IsaMeasurement m;
  std::vector<Isa> isas;
  for (const Isa isa : kIsas) {
    if (isa_supported(isa)) isas.push_back(isa);
  }
  m.fastest = isas.empty() ? Isa::sse2 : isas.front();
  if (isas.size() < 2) return m;  // nothing to choose between

  CalibrationScene<T> scene(model, accuracy, scattered);
  // Warm-up: code and data into the caches, and the slowest cost per contact.
  double slowest = 0;
  for (const Isa isa : isas) {
    const double seconds = scene.pass(kernel_table(isa), kWarmUpContacts);
    slowest = std::max(slowest, seconds / static_cast<double>(kWarmUpContacts));
  }
  std::size_t contacts = kContacts;
  if (slowest * static_cast<double>(kContacts) > kPassSeconds) {
    const auto fit = static_cast<std::size_t>(kPassSeconds / slowest);
    contacts = std::clamp<std::size_t>(fit / kGroup * kGroup, kWarmUpContacts, kContacts);
  }
  double best[3];
  std::fill(std::begin(best), std::end(best), std::numeric_limits<double>::infinity());
  for (int round = 0; round < kRounds; ++round) {
    for (std::size_t i = 0; i < isas.size(); ++i) {
      const Isa isa = isas[(i + static_cast<std::size_t>(round)) % isas.size()];
      const double seconds = scene.pass(kernel_table(isa), contacts);
      best[isa_index(isa)] = std::min(best[isa_index(isa)], seconds);
    }
  }
  for (const Isa isa : isas) {
    m.seconds[isa_index(isa)] = best[isa_index(isa)];
    if (best[isa_index(isa)] < best[isa_index(m.fastest)]) m.fastest = isa;
  }
  m.contacts = contacts;
  m.rounds = kRounds;
  m.calibration_seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return m;
}

/// One key's measurement, run once.
struct Slot {
  std::once_flag once;
  IsaMeasurement result;
};

int model_index(Model model) {
  switch (model) {
    case Model::particle:
      return 0;
    case Model::sphere:
      return 1;
    case Model::rigid:
      break;
  }
  return 2;
}

}  // namespace

template <class T>
const IsaMeasurement& measured_isa(Model model, Accuracy accuracy, bool scattered, double* spent_seconds) {
  static Slot slots[3][2][2];
  Slot& slot = slots[model_index(model)][accuracy == Accuracy::accurate ? 1 : 0][scattered ? 1 : 0];
  bool ran = false;
  std::call_once(slot.once, [&] {
    slot.result = measure<T>(model, accuracy, scattered);
    ran = true;
  });
  if (spent_seconds != nullptr) *spent_seconds = ran ? slot.result.calibration_seconds : 0.0;
  return slot.result;
}

template const IsaMeasurement& measured_isa<float>(Model, Accuracy, bool, double*);
template const IsaMeasurement& measured_isa<double>(Model, Accuracy, bool, double*);

}  // namespace detail

template <class T>
Isa fastest_isa(Model model, Accuracy accuracy, bool scattered) {
  return detail::measured_isa<T>(model, accuracy, scattered).fastest;
}

template <class T>
IsaMeasurement isa_measurement(Model model, Accuracy accuracy, bool scattered) {
  return detail::measured_isa<T>(model, accuracy, scattered);
}

template Isa fastest_isa<float>(Model, Accuracy, bool);
template Isa fastest_isa<double>(Model, Accuracy, bool);
template IsaMeasurement isa_measurement<float>(Model, Accuracy, bool);
template IsaMeasurement isa_measurement<double>(Model, Accuracy, bool);

}  // namespace collide
