// kernel/units.hpp - the kernel units of one instruction set, as its table
// (kernel/table.cpp) calls them: one unit per body model, precision and
// accuracy mode (kernel/<model>_<precision>_<mode>.cpp), each filling its
// slots of the table (kernel/loops.hpp, add_unit_loops): units of that size
// compile in a fraction of the time a unit of a model's every loop took
// (docs/decisions/0032-the-double-accurate-law-out-of-line.md has the times).
#pragma once

#include "kernel_table.hpp"
#include "lanes.hpp"

namespace collide::detail {
inline namespace COLLIDE_KERNEL_NS {

void add_particle_float_fast(KernelTable& table);
void add_particle_float_accurate(KernelTable& table);
void add_particle_double_fast(KernelTable& table);
void add_particle_double_accurate(KernelTable& table);
void add_sphere_float_fast(KernelTable& table);
void add_sphere_float_accurate(KernelTable& table);
void add_sphere_double_fast(KernelTable& table);
void add_sphere_double_accurate(KernelTable& table);
void add_rigid_float_fast(KernelTable& table);
void add_rigid_float_accurate(KernelTable& table);
void add_rigid_double_fast(KernelTable& table);
void add_rigid_double_accurate(KernelTable& table);

}  // namespace COLLIDE_KERNEL_NS
}  // namespace collide::detail
