// isa.cpp - which instruction set the CPU has, and the names of collide::Isa.
//
// Detection reads CPUID and, for AVX and AVX-512, XGETBV: a CPU may have the
// instructions while the OS does not save the wide registers on a context
// switch, and then they must not be used. GCC's __builtin_cpu_supports checks
// both, so it is what we use; it is evaluated once (a function-local static).
#include "collide/isa.hpp"

#include <cstdlib>
#include <stdexcept>
#include <string>

namespace collide {

const char* to_string(Isa isa) {
  switch (isa) {
    case Isa::automatic:
      return "auto";
    case Isa::sse2:
      return "sse2";
    case Isa::avx2:
      return "avx2";
    case Isa::avx512:
      return "avx512";
  }
  return "?";
}

const char* to_string(IsaChoice choice) {
  switch (choice) {
    case IsaChoice::forced:
      return "forced";
    case IsaChoice::environment:
      return "environment";
    case IsaChoice::measured:
      return "measured";
    case IsaChoice::baseline:
      return "baseline";
  }
  return "?";
}

Isa parse_isa(std::string_view name) {
  for (const Isa isa : {Isa::automatic, Isa::sse2, Isa::avx2, Isa::avx512}) {
    if (name == to_string(isa)) return isa;
  }
  throw std::invalid_argument("unknown instruction set '" + std::string(name) +
                              "' (expected auto, sse2, avx2 or avx512)");
}

namespace {

/// The widest ISA that both the CPU has and this build has a kernel for
/// (COLLIDE_HAVE_KERNEL_*, core/CMakeLists.txt: a clang build has no
/// AVX-512 kernel).
Isa detect() {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_cpu_init();
#if defined(COLLIDE_HAVE_KERNEL_avx512)
  // AVX-512 as the kernel is compiled for it: F, BW, DQ and VL.
  if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512dq") &&
      __builtin_cpu_supports("avx512vl")) {
    return Isa::avx512;
  }
#endif
#if defined(COLLIDE_HAVE_KERNEL_avx2)
  if (__builtin_cpu_supports("avx2")) return Isa::avx2;
#endif
#endif
  return Isa::sse2;
}

int rank(Isa isa) { return static_cast<int>(isa); }

}  // namespace

Isa best_isa() {
  static const Isa best = detect();
  return best;
}

bool isa_supported(Isa isa) { return isa == Isa::automatic || rank(isa) <= rank(best_isa()); }

Isa default_isa() {
  const char* env = std::getenv("COLLIDE_ISA");
  if (env == nullptr || *env == '\0') return best_isa();
  Isa isa;
  try {
    isa = parse_isa(env);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("COLLIDE_ISA: ") + e.what());
  }
  if (isa == Isa::automatic) return best_isa();
  if (!isa_supported(isa)) {
    throw std::invalid_argument(std::string("COLLIDE_ISA=") + env + ": this CPU supports up to " +
                                to_string(best_isa()));
  }
  return isa;
}

Isa resolve_isa(Isa requested) {
  if (requested == Isa::automatic) return default_isa();
  if (!isa_supported(requested)) {
    throw std::invalid_argument(std::string("instruction set ") + to_string(requested) +
                                " is not supported by this CPU or build (it supports up to " + to_string(best_isa()) +
                                ")");
  }
  return requested;
}

}  // namespace collide
