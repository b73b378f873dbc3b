// kernel/models.hpp - the units of one body model each (kernel/particle.cpp,
// kernel/sphere.cpp, kernel/rigid.cpp), as the table of their ISA
// (kernel/table.cpp) calls them: each fills its model's slots of both
// precisions' loops.
#pragma once

#include "kernel_table.hpp"
#include "lanes.hpp"

namespace collide::detail {
inline namespace COLLIDE_KERNEL_NS {

void add_particle_loops(KernelTable& table);
void add_sphere_loops(KernelTable& table);
void add_rigid_loops(KernelTable& table);

}  // namespace COLLIDE_KERNEL_NS
}  // namespace collide::detail
