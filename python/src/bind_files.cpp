// python/src/bind_files.cpp - scene files: collide.read_scene, collide.load
// (CSV or binary, the binary one mapped in place, collide.MappedFile) and
// collide.write_scene / save, and scene-file errors as Python exceptions.
//
// Design notes
// ------------
// * Reading and writing are the library's (collide/io/scene_io.hpp,
//   scene_npz.hpp): the same readers, rules, messages and writers as the
//   `collide` command, without the GIL.
// * A binary file's columns stay in its read-only mapping where they lie one
//   stride apart (as collide's writer places them): the arrays are views
//   whose base is a MappedFile, which keeps the mapping alive. The inverses
//   are computed and v, w copied, since a solve writes them.
// * An operating-system error (missing file, directory, no permission) is
//   OSError(errno, message, path), which Python maps to FileNotFoundError,
//   IsADirectoryError, PermissionError...; a bad content is ValueError with
//   the library's message (file, line, row, column).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstdint>
#include <exception>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "bindings.hpp"
#include "collide/io/output_file.hpp"
#include "collide/io/scene.hpp"
#include "collide/io/scene_io.hpp"
#include "collide/io/scene_npz.hpp"
#include "scene.hpp"

namespace collide::python {
namespace {

py::tuple read_scene_py(const std::string& bodies_csv, const std::string& contacts_csv, const py::object& dtype_in) {
  const Dtype d = parse_dtype(dtype_in);
  return with_dtype(d, [&](auto tag) {
    using T = decltype(tag);
    Scene<T> s;
    {
      py::gil_scoped_release release;
      const BodyTable<T> table = read_bodies<T>(bodies_csv);
      s.contacts = read_contacts<T>(contacts_csv, table.size());
      s.bodies = to_body_buffer(table);
    }
    return scene_objects<T>(std::as_const(s.bodies).view(), s.contacts.view(), d);
  });
}

/// What keeps a loaded file's mapping alive: the base object of every array
/// that points into it. `address` and `size` say where the mapping lies, so
/// a caller (and the tests) can tell a view from a copy.
struct MappedFile {
  std::shared_ptr<const void> owner;
  std::string path;
  std::uintptr_t address = 0;
  std::size_t size = 0;

  [[nodiscard]] bool holds(const void* p, std::size_t bytes) const {
    const auto a = reinterpret_cast<std::uintptr_t>(p);
    return size != 0 && a >= address && a + bytes <= address + size;
  }
};

/// A (rows, n) array of `dtype` over columns `cols` where they lie, when they
/// lie one stride apart inside the mapping of `file` (a MappedFile), read
/// only; else a copy. One column gives an (n,) array.
template <class U>
py::array columns_array(const py::dtype& dtype, const std::vector<const U*>& cols, std::size_t n,
                        const py::object& file) {
  const MappedFile& mapped = file.cast<const MappedFile&>();
  bool in_place = n > 0;
  std::ptrdiff_t stride = 0;
  for (std::size_t r = 0; r < cols.size() && in_place; ++r) {
    in_place = mapped.holds(cols[r], n * sizeof(U));
    if (r == 1) stride = reinterpret_cast<const char*>(cols[1]) - reinterpret_cast<const char*>(cols[0]);
    if (r >= 1 && in_place) {
      in_place = stride >= static_cast<std::ptrdiff_t>(n * sizeof(U)) &&
                 reinterpret_cast<const char*>(cols[r]) - reinterpret_cast<const char*>(cols[r - 1]) == stride;
    }
  }
  if (!in_place) return copy_rows<U>(dtype, cols.data(), cols.size(), n);
  std::vector<py::ssize_t> shape, strides;
  if (cols.size() > 1) {
    shape.push_back(static_cast<py::ssize_t>(cols.size()));
    strides.push_back(stride);
  }
  shape.push_back(static_cast<py::ssize_t>(n));
  strides.push_back(sizeof(U));
  py::array a(dtype, shape, strides, cols[0], file);
  set_read_only(a);  // the mapping is private and read-only: the array says so
  return a;
}

template <class T>
py::tuple load_t(const std::string& bodies_path, const std::string& contacts_path, Dtype d) {
  std::shared_ptr<LoadedBodies<T>> lb;
  std::shared_ptr<LoadedContacts<T>> lc;
  {
    py::gil_scoped_release release;
    lb = std::make_shared<LoadedBodies<T>>(
        load_bodies<T>(bodies_path, scene_format_of(bodies_path), BodyRules::by_caller));
  }
  // The arrays the solver takes and writes: the inverses, and v and w
  // copied, since a solve writes them; q and p stay in the file. Filled in
  // the pass that checks the bodies' rules (one read of the file), before
  // the contacts file is read.
  const BodyColumns<T>& bc = lb->columns();
  const std::size_t n = bc.count;
  const auto rows = static_cast<py::ssize_t>(n);
  py::array inv_mass = new_array(d, {rows});
  py::array inv_inertia = new_array(d, {3, rows});
  py::array vel = new_array(d, {3, rows});
  py::array ang = new_array(d, {3, rows});
  {
    py::gil_scoped_release release;
    lb->fill_solve_arrays(data<T>(inv_mass), vec3<T>(inv_inertia), vec3<T>(vel), vec3<T>(ang));
    lc = std::make_shared<LoadedContacts<T>>(
        load_contacts<T>(contacts_path, scene_format_of(contacts_path), lb->size()));
  }
  const auto file_object = [](std::shared_ptr<const void> owner, const std::string& path, std::string_view bytes) {
    return py::cast(MappedFile{std::move(owner), path, reinterpret_cast<std::uintptr_t>(bytes.data()), bytes.size()});
  };
  const py::object bfile = file_object(lb, bodies_path, lb->mapped_bytes());
  const py::object cfile = file_object(lc, contacts_path, lc->mapped_bytes());
  const py::dtype dt = numpy_dtype(d);

  const auto cols = [&bc](std::size_t first, std::size_t count) {
    return std::vector<const T*>(bc.column.begin() + first, bc.column.begin() + first + count);
  };
  py::object bodies = py::cast(Bodies(inv_mass, inv_inertia, columns_array<T>(dt, cols(4, 4), n, bfile),
                                      columns_array<T>(dt, cols(8, 3), n, bfile), vel, ang));

  const ContactView<T>& v = lc->view();
  const std::size_t m = v.count;
  const py::dtype u32 = py::dtype::of<std::uint32_t>();
  const py::object mu = v.mu ? py::object(columns_array<T>(dt, {v.mu}, m, cfile)) : py::none();
  py::object contacts = py::cast(
      Contacts(columns_array<BodyIndex>(u32, {v.a}, m, cfile), columns_array<BodyIndex>(u32, {v.b}, m, cfile),
               columns_array<T>(dt, {v.c.x, v.c.y, v.c.z}, m, cfile),
               columns_array<T>(dt, {v.n.x, v.n.y, v.n.z}, m, cfile), columns_array<T>(dt, {v.e}, m, cfile), 1.0, mu));
  return py::make_tuple(bodies, contacts);
}

py::tuple load_py(const std::string& bodies_path, const std::string& contacts_path, const py::object& dtype_in) {
  Dtype d = Dtype::f64;
  if (!dtype_in.is_none()) {
    d = parse_dtype(dtype_in);
  } else if (scene_format_of(bodies_path) == SceneFormat::npz) {
    // A binary scene in its own precision: mapped, not converted. Binary
    // files of two precisions leave the choice to the caller, as `collide
    // solve` does without --precision.
    const NpyType bodies = npz_scene_precision(NpzArchive::map(bodies_path));
    if (scene_format_of(contacts_path) == SceneFormat::npz) {
      const NpyType contacts = npz_scene_precision(NpzArchive::map(contacts_path));
      if (contacts != bodies) {
        const auto name = [](NpyType t) { return t == NpyType::f4 ? "float32" : "float64"; };
        throw py::value_error(bodies_path + " holds " + name(bodies) + " values but " + contacts_path + " " +
                              name(contacts) +
                              ": say which precision to load the scene in with "
                              "dtype=numpy.float32 or dtype=numpy.float64");
      }
    }
    d = bodies == NpyType::f4 ? Dtype::f32 : Dtype::f64;
  }
  return with_dtype(d, [&](auto tag) { return load_t<decltype(tag)>(bodies_path, contacts_path, d); });
}

/// Writes the scene with the library's writers, in the format each name
/// says, after validate(): physical units from the inverses (1/0 gives inf),
/// rows formatted in parallel blocks, a few blocks in memory at a time, both
/// files committed, or neither.
void write_scene_py(const std::string& bodies_path, const std::string& contacts_path, const Bodies& bodies,
                    const Contacts& contacts) {
  require_same_dtype(bodies, contacts);
  with_dtype(bodies.dtype, [&](auto tag) {
    using T = decltype(tag);
    validate_or_throw<T>(bodies, contacts);
    const BodyView<T> bv = bodies.view<T>();
    const ContactView<T> cv = contacts.view<T>();
    py::gil_scoped_release release;
    const BodyTable<T> table = to_body_table(const_view(bv));
    OutputFile ob(bodies_path), oc(contacts_path);
    write_body_table(ob, scene_format_of(bodies_path), columns_of(table));
    write_contacts(oc, scene_format_of(contacts_path), cv);
    ob.commit();
    oc.commit();
  });
}

}  // namespace

void register_files(py::module_& m) {
  py::class_<MappedFile>(m, "MappedFile",
                         "A scene file mapped into memory: the base of the arrays collide.load() leaves in it.")
      .def_readonly("path", &MappedFile::path)
      .def_readonly("address", &MappedFile::address)
      .def_readonly("size", &MappedFile::size)
      .def("__repr__", [](const MappedFile& f) {
        return "collide.MappedFile(" + py::repr(py::str(f.path)).cast<std::string>() + ", " + std::to_string(f.size) +
               " bytes)";
      });
  m.def("load", &load_py, py::arg("bodies"), py::arg("contacts"), py::kw_only(), py::arg("dtype") = py::none());
  m.def("read_scene", &read_scene_py, py::arg("bodies_csv"), py::arg("contacts_csv"), py::kw_only(), py::arg("dtype"));
  m.def("write_scene", &write_scene_py, py::arg("bodies_csv"), py::arg("contacts_csv"), py::arg("bodies"),
        py::arg("contacts"));

  // Every SceneError (thrown by the library, with or without the GIL) as
  // OSError(errno, message, path) for an operating-system error, else as
  // ValueError with the library's message. By value: pybind11's translator
  // is a void (*)(std::exception_ptr).
  py::register_exception_translator([](std::exception_ptr p) {  // NOLINT(performance-unnecessary-value-param)
    try {
      if (p) std::rethrow_exception(p);
    } catch (const SceneError& e) {
      if (e.os_error() != 0) {
        PyErr_SetObject(PyExc_OSError, py::make_tuple(e.os_error(), e.reason(), e.file()).ptr());
      } else {
        PyErr_SetString(PyExc_ValueError, e.what());
      }
    }
  });
}

}  // namespace collide::python
