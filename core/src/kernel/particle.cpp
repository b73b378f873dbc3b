// kernel/particle.cpp - the particle model's loops, in the lanes of one instruction set
// (kernel/loops.hpp; compiled once per ISA, core/CMakeLists.txt).
#include "kernel/loops.hpp"
#include "kernel/models.hpp"

namespace collide::detail {
inline namespace COLLIDE_KERNEL_NS {

void add_particle_loops(KernelTable& table) {
  add_model_loops<ParticleModel, float>(table.loops_float);
  add_model_loops<ParticleModel, double>(table.loops_double);
}

}  // namespace COLLIDE_KERNEL_NS
}  // namespace collide::detail
