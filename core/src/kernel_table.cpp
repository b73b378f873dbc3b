// kernel_table.cpp - the loops of an instruction set this build has, and of
// one job (kernel_table.hpp).
#include "kernel_table.hpp"

namespace collide::detail {

KernelTable& writable_kernel_table(Isa isa) {
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

const KernelTable& kernel_table(Isa isa) { return writable_kernel_table(isa); }

const OneLaneTable& one_lane_table() { return writable_one_lane_table(); }

template <class T>
JobKernels<T> job_kernels(const KernelTable& table, const KernelJob<T>& job, bool simd) {
  const KernelLoops<T>& loops = of_precision<T>(table.loops_float, table.loops_double);
  const GroupLoops<T>& one_lane = of_precision<T>(one_lane_table().loops_float, one_lane_table().loops_double);
  const auto model = static_cast<std::size_t>(job.model());
  const std::size_t mode = job.accurate ? 1 : 0;
  const std::size_t friction = job.friction ? 1 : 0;
  const std::size_t layout = job.packed() ? 1 : 0;
  JobKernels<T> k;
  if (job.accumulates()) {
    // Runs of tiny batches take the one-lane loop contact by contact; the
    // geometry a prepared solve forms once is the repeat mode's.
    k.one_lane = job.stepped ? one_lane.accumulate_step[model][layout] : one_lane.accumulate[model][friction][layout];
    if (simd) {
      k.groups =
          job.stepped ? loops.groups.accumulate_step[model][layout] : loops.groups.accumulate[model][friction][layout];
    } else {
      k.groups = k.one_lane;
    }
    if (!job.accurate && !job.friction) k.geometry = loops.geometry[model][layout];
    return k;
  }
  k.one_lane = job.stepped ? one_lane.step[model][layout] : one_lane.solve[model][mode][friction][layout];
  if (simd) {
    k.groups = job.stepped ? loops.groups.step[model][layout] : loops.groups.solve[model][mode][friction][layout];
  } else {
    k.groups = k.one_lane;
  }
  if (!job.accurate && !job.friction) {
    if (!job.stepped) k.run_pieces = loops.run[model][layout];
    k.geometry = loops.geometry[model][layout];
    k.walk = loops.walk[model][layout];
  }
  return k;
}

template JobKernels<float> job_kernels<float>(const KernelTable&, const KernelJob<float>&, bool);
template JobKernels<double> job_kernels<double>(const KernelTable&, const KernelJob<double>&, bool);

}  // namespace collide::detail
