// kernel/sphere_float_accumulated.cpp - a kernel unit (kernel/units.hpp): the
// sphere model's float loops of the accumulated passes (fast mode), in the
// lanes of the ISA it is compiled for (kernel/loops.hpp; once per ISA,
// core/CMakeLists.txt).
#include "kernel/loops.hpp"
#include "kernel/units.hpp"

namespace collide::detail {
inline namespace COLLIDE_KERNEL_NS {

void add_sphere_float_accumulated(KernelTable& table) { add_accumulated_unit_loops<SphereModel, float>(table); }

}  // namespace COLLIDE_KERNEL_NS
}  // namespace collide::detail
