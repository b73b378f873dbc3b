// kernel/scalar.cpp - the one-lane loops of every model (kernel/loops.hpp in
// ScalarLanes): the scalar path, and the tail of every SIMD range on every
// ISA. Compiled once, for the baseline, with its kernel units
// (core/CMakeLists.txt).
#include "kernel/loops.hpp"
#include "kernel_table.hpp"

namespace collide::detail {
namespace {

OneLaneTable make_one_lane_table() {
  OneLaneTable table;
  add_one_lane_loops<ParticleModel, float>(table.loops_float);
  add_one_lane_loops<SphereModel, float>(table.loops_float);
  add_one_lane_loops<RigidModel, float>(table.loops_float);
  add_one_lane_loops<ParticleModel, double>(table.loops_double);
  add_one_lane_loops<SphereModel, double>(table.loops_double);
  add_one_lane_loops<RigidModel, double>(table.loops_double);
  return table;
}

}  // namespace

OneLaneTable& writable_one_lane_table() {
  static OneLaneTable table = make_one_lane_table();
  return table;
}

}  // namespace collide::detail
