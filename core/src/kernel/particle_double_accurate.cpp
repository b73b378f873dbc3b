// kernel/particle_double_accurate.cpp - a kernel unit (kernel/units.hpp): the
// particle model's double loops of the accurate mode, in the lanes of the ISA
// it is compiled for (kernel/loops.hpp; once per ISA, core/CMakeLists.txt).
#include "kernel/loops.hpp"
#include "kernel/units.hpp"

namespace collide::detail {
inline namespace COLLIDE_KERNEL_NS {

void add_particle_double_accurate(KernelTable& table) { add_unit_loops<ParticleModel, double, AccurateMode>(table); }

}  // namespace COLLIDE_KERNEL_NS
}  // namespace collide::detail
