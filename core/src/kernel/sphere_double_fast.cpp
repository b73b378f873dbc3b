// kernel/sphere_double_fast.cpp - a kernel unit (kernel/units.hpp): the sphere
// model's double loops of the fast mode, with the velocity step's and the
// run's, in the lanes of the ISA it is compiled for (kernel/loops.hpp; once
// per ISA, core/CMakeLists.txt).
#include "kernel/loops.hpp"
#include "kernel/units.hpp"

namespace collide::detail {
inline namespace COLLIDE_KERNEL_NS {

void add_sphere_double_fast(KernelTable& table) { add_unit_loops<SphereModel, double, FastMode>(table); }

}  // namespace COLLIDE_KERNEL_NS
}  // namespace collide::detail
