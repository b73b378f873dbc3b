// kernel/rigid_float_accumulated.cpp - a kernel unit (kernel/units.hpp): the
// rigid model's float loops of the accumulated passes (fast mode), in the
// lanes of the ISA it is compiled for (kernel/loops.hpp; once per ISA,
// core/CMakeLists.txt).
#include "kernel/loops.hpp"
#include "kernel/units.hpp"

namespace collide::detail {
inline namespace COLLIDE_KERNEL_NS {

void add_rigid_float_accumulated(KernelTable& table) { add_accumulated_unit_loops<RigidModel, float>(table); }

}  // namespace COLLIDE_KERNEL_NS
}  // namespace collide::detail
