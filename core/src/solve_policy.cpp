// solve_policy.cpp - the choices of solve_policy.hpp.
#include "solve_policy.hpp"

#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "isa_calibration.hpp"

namespace collide::detail {
namespace {

/// Positions sampled per contiguous batch by scattered_contacts.
constexpr std::size_t kLocalitySamples = 64;
/// A contact's body "follows" the one of the contact before it when their
/// indices differ by less than this: the records are a few lines apart and
/// streamed, as in the pairs layout (a difference of 2).
constexpr std::int64_t kNearBodies = 64;

}  // namespace

IsaChoice isa_choice_for(Isa requested) {
  if (requested != Isa::automatic) return IsaChoice::forced;
  const char* env = std::getenv("COLLIDE_ISA");
  if (env == nullptr || *env == '\0' || std::string_view(env) == to_string(Isa::automatic)) {
    return IsaChoice::measured;
  }
  return IsaChoice::environment;
}

const KernelTable* fixed_kernels(Isa requested, IsaChoice choice) {
  return choice == IsaChoice::measured ? nullptr : &kernel_table(resolve_isa(requested));
}

template <class T>
IsaPick pick_isa(Path path, Accuracy accuracy, IsaChoice choice, const KernelTable* fixed, Model model,
                 std::size_t scattered, std::size_t contacts) {
  if (path == Path::scalar) return {&kernel_table(Isa::sse2), IsaChoice::baseline, 0.0};
  if (fixed != nullptr) return {fixed, choice, 0.0};
  double spent = 0;
  const Isa isa = measured_isa<T>(model, accuracy, 2 * scattered > contacts, &spent).fastest;
  return {&kernel_table(isa), IsaChoice::measured, spent};
}

template IsaPick pick_isa<float>(Path, Accuracy, IsaChoice, const KernelTable*, Model, std::size_t, std::size_t);
template IsaPick pick_isa<double>(Path, Accuracy, IsaChoice, const KernelTable*, Model, std::size_t, std::size_t);

/// A caller who hands the contacts over already grouped by level has every
/// batch consecutive, but the bodies of a debris scene are still read at
/// random, and reading them in place from SoA arrays (a line per component
/// per body) is far slower than packing them
/// (docs/decisions/0005-packed-records-for-scattered-contacts.md): so
/// consecutive batches of 1024 contacts or more are sampled at
/// kLocalitySamples evenly spaced places, and count as scattered when most
/// samples find both bodies far from those of the contact before. The sample reads a few hundred
/// indices: nothing beside the solve.
bool prepares_contacts(const Schedule& schedule) {
  if (schedule.order() != Order::colour) return false;
  for (std::size_t k = 0; k < schedule.batch_count(); ++k) {
    if (!schedule.batch_is_contiguous(k)) return true;
  }
  return false;
}

bool steps_prepared_contacts(std::size_t passes, bool accurate, bool friction) {
  return passes > 1 && !accurate && !friction;
}

std::size_t scattered_contacts(const Schedule& schedule, const BodyIndex* a, const BodyIndex* b) {
  std::size_t n = 0;
  const std::uint32_t* order = schedule.solve_order();
  // A colour of a window holds every few contacts of a stretch of the input:
  // not consecutive, but in a pile or a chain in a broadphase's order their
  // bodies follow one another (the kernel then loads them as vectors,
  // kernel/loops.hpp), so the colour order samples those batches too.
  const bool sample_gathered = schedule.order() == Order::colour;
  for (std::size_t k = 0; k < schedule.batch_count(); ++k) {
    const std::size_t begin = schedule.batch_begin(k);
    const std::size_t size = schedule.batch_begin(k + 1) - begin;
    if (!schedule.batch_is_contiguous(k) && !(sample_gathered && size >= 1024)) {
      n += size;
      continue;
    }
    if (size < 1024) continue;
    std::size_t far = 0;
    for (std::size_t s = 0; s < kLocalitySamples; ++s) {
      const std::size_t i = begin + 1 + s * (size - 1) / kLocalitySamples;
      const std::size_t c = order[i];
      const std::size_t before = order[i - 1];
      const auto apart = [&](const BodyIndex* index) {
        return std::abs(static_cast<std::int64_t>(index[c]) - static_cast<std::int64_t>(index[before])) >= kNearBodies;
      };
      far += apart(a) && apart(b) ? 1 : 0;
    }
    if (2 * far > kLocalitySamples) n += size;
  }
  return n;
}

/// Packing reads every body once and writes v, w back once (streaming,
/// parallel); it pays when the scattered contacts would otherwise touch a
/// line per component per body at random. At a quarter as many scattered
/// contacts as bodies the two cost about the same; below that, or in scenes
/// that stream (pairs), the SoA arrays are used in place
/// (docs/decisions/0005-packed-records-for-scattered-contacts.md).
bool should_pack(BodyLayout layout, std::size_t scattered, std::size_t bodies) {
  switch (layout) {
    case BodyLayout::soa:
      return false;
    case BodyLayout::packed:
      return true;
    case BodyLayout::automatic:
      break;
  }
  return scattered >= 1024 && 4 * scattered >= bodies;
}

}  // namespace collide::detail
