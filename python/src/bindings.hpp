// python/src/bindings.hpp - the registration function of each topic of the
// collide._collide extension, which module.cpp calls in order.
#pragma once

#include <pybind11/pybind11.h>

namespace collide::python {

namespace py = pybind11;

/// Bodies, Contacts, generate, from_physical, choose_model, model_misfit
/// (bind_scene.cpp).
void register_scene(py::module_& m);
/// PackedBodies (its field views and unpack methods), packed_dtype,
/// packed_alignment, pack_into (bind_packed.cpp).
void register_packed(py::module_& m);
/// Schedule, Solver, Reference, reference_solve, impulse_error,
/// conservation_drift, the error constants and the instruction-set queries
/// (bind_solve.cpp).
void register_solve(py::module_& m);
/// Islands, islands (bind_islands.cpp).
void register_islands(py::module_& m);
/// MappedFile, load, read_scene, write_scene and the translation of scene-
/// file errors (bind_files.cpp).
void register_files(py::module_& m);
/// report, report_hard (bind_report.cpp).
void register_report(py::module_& m);

}  // namespace collide::python
