// kernel_table.cpp - the kernels of an instruction set this build has
// (kernel_table.hpp).
#include "kernel_table.hpp"

namespace collide::detail {

const KernelTable& kernel_table(Isa isa) {
#if defined(__x86_64__)
  switch (isa) {
#if defined(COLLIDE_HAVE_KERNEL_avx512)
    case Isa::avx512:
      return kernel_table_avx512();
#endif
#if defined(COLLIDE_HAVE_KERNEL_avx2)
    case Isa::avx2:
      return kernel_table_avx2();
#endif
    default:
      break;
  }
  return kernel_table_sse2();
#else
  (void)isa;
  return kernel_table_native();
#endif
}

}  // namespace collide::detail
