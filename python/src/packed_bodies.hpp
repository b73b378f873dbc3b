// python/src/packed_bodies.hpp - collide.PackedBodies: bodies in the
// library's packed records (collide/packed.hpp), over the caller's array.
//
// Design notes
// ------------
// * The records are the caller's array, structured (packed_dtype(), built
//   from the C++ offsets) or (N, k) floats, checked for dtype, width,
//   contiguity and alignment (TypeError) and solved in place by the
//   library's packed overloads; values are checked by validate() for packed
//   views, so records and SoA get the same messages.
// * The record type is the model. Rigid records hold no inverse mass: it is
//   a second caller's array, (N,) beside the records
//   (PackedView<PackedRigid<T>>::inv_mass), checked like any array argument
//   and only read by the solve.
// * The steps of a solve on records (validate_values, build_schedule,
//   solve_model, run_solve) are overloads beside those of SoA bodies
//   (scene.hpp).
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstddef>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "arrays.hpp"
#include "collide/packed.hpp"
#include "scene.hpp"

namespace collide::python {

/// N packed bodies over the caller's records, with no copy: a 1-D array of
/// the record dtype (packed_dtype()), or a C-contiguous (N, k) float array
/// whose rows are the records (k values of T per record, padding included).
/// v and w are updated in place. Rigid records hold no inverse mass
/// (collide/packed.hpp): theirs is the caller's (N,) array `inv_mass`,
/// beside them, which the solve only reads.
struct PackedBodies {
  py::array records;
  std::optional<py::array> inv_mass;  ///< rigid records only
  Model model = Model::rigid;
  Dtype dtype = Dtype::f32;
  std::size_t count = 0;

  PackedBodies(const py::object& records_in, const std::string& model_name, const py::object& inv_mass_in);

  template <class Record>
  PackedView<Record> view() const {
    using T = typename PackedValue<Record>::type;
    PackedView<Record> v;
    v.count = count;
    v.bodies = data<Record>(records);
    if constexpr (std::is_same_v<Record, PackedRigid<T>>) v.inv_mass = data<T>(*inv_mass);
    return v;
  }

 private:
  void set_model(const py::array& a, const std::optional<Model>& requested, const std::string& model_name,
                 bool has_inv_mass);
  void set_inv_mass(const py::object& inv_mass_in);
};

/// The records (written whole by a solve) and rigid records' inverse
/// masses (read) as the bytes a solve touches (add_bytes of arrays.hpp).
void add_bytes(std::vector<ArrayBytes>& out, const PackedBodies& b);

/// f(PackedView<Record>) for the records' type, with value type T.
template <class T, class F>
decltype(auto) with_records(const PackedBodies& b, F&& f) {
  switch (b.model) {
    case Model::sphere:
      return f(b.view<PackedSphere<T>>());
    case Model::particle:
      return f(b.view<PackedParticle<T>>());
    case Model::rigid:
      break;
  }
  return f(b.view<PackedRigid<T>>());
}

// The steps of a solve on records (those of SoA bodies are in scene.hpp).

template <class T>
Validation validate_values(const PackedBodies& b, const ContactView<T>& cv, const ImpulseView<T>& jv) {
  return with_records<T>(b, [&](const auto& records) { return validate(records, cv, jv); });
}

/// Packed records give the inverse masses in place (rigid ones beside them).
template <class T>
void build_schedule(Schedule& schedule, const ContactView<T>& cv, const PackedBodies& b) {
  with_records<T>(b, [&](const auto& records) { schedule.build(cv, records); });
}

/// The record type is the model.
template <class T>
Model solve_model(const PackedBodies& b, const ContactView<T>&, const std::optional<Model>& requested, bool) {
  if (requested && *requested != b.model) {
    throw py::value_error(std::string("model '") + to_string(*requested) + "' does not match the records: they are " +
                          to_string(b.model) + " records, and the record type is the model");
  }
  return b.model;
}

template <class T>
SolveStats run_solve(const Solver& solver, Model, const PackedBodies& b, const ContactView<T>& cv,
                     const ImpulseView<T>& jv, const Schedule& schedule) {
  return with_records<T>(b, [&](const auto& records) { return solver.solve(records, cv, jv, schedule); });
}

}  // namespace collide::python
