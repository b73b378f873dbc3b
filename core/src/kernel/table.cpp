// kernel/table.cpp - the table of one instruction set (kernel_table.hpp):
// its lanes, and the loops of its kernel units (kernel/units.hpp). Compiled
// once per ISA with the units (core/CMakeLists.txt).
#include "kernel/units.hpp"
#include "kernel_table.hpp"
#include "lanes.hpp"

#define COLLIDE_CONCAT_(a, b) a##b
#define COLLIDE_CONCAT(a, b) COLLIDE_CONCAT_(a, b)

namespace collide::detail {
namespace {

Isa this_isa() {
#if defined(COLLIDE_KERNEL_ISA_avx512)
  return Isa::avx512;
#elif defined(COLLIDE_KERNEL_ISA_avx2)
  return Isa::avx2;
#else
  return Isa::sse2;
#endif
}

KernelTable make_table() {
  KernelTable table;
  table.isa = this_isa();
  table.lanes_float = SimdLanes<float>::size();
  table.lanes_double = SimdLanes<double>::size();
  add_particle_float_fast(table);
  add_particle_float_accurate(table);
  add_particle_double_fast(table);
  add_particle_double_accurate(table);
  add_sphere_float_fast(table);
  add_sphere_float_accurate(table);
  add_sphere_double_fast(table);
  add_sphere_double_accurate(table);
  add_rigid_float_fast(table);
  add_rigid_float_accurate(table);
  add_rigid_double_fast(table);
  add_rigid_double_accurate(table);
  return table;
}

}  // namespace

KernelTable& COLLIDE_CONCAT(kernel_table_, COLLIDE_KERNEL_NS)() {
  static KernelTable table = make_table();
  return table;
}

}  // namespace collide::detail
