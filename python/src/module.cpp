// python/src/module.cpp - the `collide._collide` extension: a thin shell over
// the library for NumPy arrays, one registration function per topic.
//
// Design notes
// ------------
// * Each topic is a file of its own: the NumPy array checks and views
//   (arrays.hpp), Bodies and Contacts and the scenes made from Python
//   (bind_scene.cpp), packed records (bind_packed.cpp), solving, schedules,
//   the reference and the instruction sets (bind_solve.cpp), the islands of
//   a scene (bind_islands.cpp), scene files
//   (bind_files.cpp), the report (bind_report.cpp); Ctrl-C during a solve
//   (interrupt.hpp) serves bind_solve.cpp. The collide package
//   (python/collide/__init__.py) gives the public functions their Python
//   signatures and documentation over these.
// * The rules are the library's: validate() for arrays in kernel units,
//   collide/rules.hpp (through the scene files' column screen) for physical
//   units, the library's readers and writers for files. The module adds no
//   rule of its own; what it checks itself is the shape of its arguments.
// * Errors: TypeError for an argument of the wrong kind or layout,
//   ValueError for a bad value or option. The library's std::invalid_argument
//   (a bad index, count or option name, with its message) arrives as
//   ValueError by pybind11's own translation; collide::SceneError by the
//   translator bind_files.cpp registers (OSError or ValueError).
#include <pybind11/pybind11.h>

#include "bindings.hpp"

PYBIND11_MODULE(_collide, m) {
  using namespace collide::python;
  m.doc() = "collide: batched rigid-body collision impulses (the C++ extension; use the collide package)";
  register_scene(m);
  register_packed(m);
  register_solve(m);
  register_islands(m);
  register_files(m);
  register_report(m);
}
