// python/src/bind_islands.cpp - collide.islands: the islands of a scene
// (collide/islands.hpp) as NumPy arrays.
//
// Design notes
// ------------
// * The library computes them (islands(), without the GIL) and checks the
//   indices itself: its std::invalid_argument ("collide::islands:
//   contacts.b[7] = 80: out of range (80 bodies)") arrives as ValueError
//   (module.cpp). Nothing else is checked: islands read only the indices and
//   the inverse masses, and any inverse mass is a verdict (0 or not).
// * The arrays are read-only views of the library's vectors, kept alive by
//   the Islands object they belong to: nothing is copied.
// * Bodies or PackedBodies, as for Schedule: packed records give their
//   inverse masses in place.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "collide/islands.hpp"
#include "packed_bodies.hpp"
#include "scene.hpp"

namespace collide::python {
namespace {

/// The islands of one scene, owning the library's result.
struct PyIslands {
  Islands islands;

  /// A read-only (n,) uint32 view of `values`, kept alive by `self`.
  static py::array view(const py::object& self, const Labels& values) {
    py::array a(py::dtype::of<std::uint32_t>(), {static_cast<py::ssize_t>(values.size())}, {sizeof(std::uint32_t)},
                values.data(), self);
    set_read_only(a);
    return a;
  }
};

/// The islands of SoA bodies (the inverse masses of the arrays).
template <class T>
Islands islands_of(const ContactView<T>& cv, const Bodies& b, int threads) {
  return islands(cv, b.view<T>(), threads);
}

/// The islands of packed records (the inverse masses in place).
template <class T>
Islands islands_of(const ContactView<T>& cv, const PackedBodies& b, int threads) {
  return with_records<T>(b, [&](const auto& records) { return islands(cv, records, threads); });
}

template <class B>
std::unique_ptr<PyIslands> islands_py(const B& bodies, const Contacts& contacts, int threads) {
  require_same_dtype(bodies, contacts);
  auto out = std::make_unique<PyIslands>();
  with_dtype(bodies.dtype, [&](auto tag) {
    using T = decltype(tag);
    const ContactView<T> cv = contacts.view<T>();
    py::gil_scoped_release release;
    out->islands = islands_of<T>(cv, bodies, threads);
  });
  return out;
}

}  // namespace

void register_islands(py::module_& m) {
  py::class_<PyIslands>(m, "Islands")
      .def_property_readonly("labels",
                             [](const py::object& self) {
                               return PyIslands::view(self, self.cast<const PyIslands&>().islands.contact_island);
                             })
      .def_property_readonly("body_labels",
                             [](const py::object& self) {
                               return PyIslands::view(self, self.cast<const PyIslands&>().islands.body_island);
                             })
      .def_property_readonly("sizes",
                             [](const py::object& self) {
                               return PyIslands::view(self, self.cast<const PyIslands&>().islands.island_contacts);
                             })
      .def_property_readonly("count", [](const PyIslands& s) { return s.islands.count(); })
      .def_property_readonly("largest", [](const PyIslands& s) { return s.islands.largest; })
      .def_property_readonly("largest_label", [](const PyIslands& s) { return s.islands.largest_island; })
      .def("__len__", [](const PyIslands& s) { return s.islands.count(); })
      .def("__repr__",
           [](const PyIslands& s) {
             const Islands& i = s.islands;
             std::string text = "collide.Islands(" + counted(i.count(), "island", "islands") + " of " +
                                counted(i.contact_island.size(), "contact", "contacts") + " over " +
                                counted(i.body_island.size(), "body", "bodies");
             if (i.count() > 0) {
               text += "; the largest, island " + std::to_string(i.largest_island) + ", has " +
                       counted(i.largest, "contact", "contacts");
             }
             return text + ")";
           })
      .def_property_readonly_static("NONE", [](const py::object&) { return Islands::kNone; });
  m.def("islands", &islands_py<Bodies>, py::arg("bodies"), py::arg("contacts"), py::kw_only(), py::arg("threads") = 0);
  m.def("islands", &islands_py<PackedBodies>, py::arg("bodies"), py::arg("contacts"), py::kw_only(),
        py::arg("threads") = 0);
}

}  // namespace collide::python
