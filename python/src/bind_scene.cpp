// python/src/bind_scene.cpp - collide.Bodies and collide.Contacts, and the
// scenes made from Python: generated (collide.generate), from physical
// units (collide.from_physical), and the questions a scene answers about
// its model (choose_model, model_misfit).
//
// Design notes
// ------------
// * The constructors check only the arrays (arrays.hpp): dtype, shape,
//   layout, lengths. Values are the library's to judge, when they are used.
// * from_physical applies the library's rules for physical units
//   (collide/rules.hpp) through the scene files' own column screen
//   (first_body_defect, collide/io/scene_io.hpp): the arrays are the
//   seventeen columns of a bodies file, with no copy, so Python refuses
//   what the file readers refuse, with their reason; the message names the
//   body and the column, "from_physical: body 3, column 'm': mass must be
//   > 0, got -1". The inverses are the readers' too (inverses_of). float64
//   arrays for a float32 result are scene values, rounded to float as the
//   readers round them (narrow_bodies, collide/io/scene_values.hpp), and a
//   value beyond float is refused with the readers' reason, not made inf.
// * scene_values rounds a float64 array into a float32 one the same way, for
//   collide.dask's workers, which read their rows of a binary file
//   themselves.
// * inverses gives those inverses alone, without the rules and without a
//   copy of anything else: for a caller that holds columns a reader has
//   already checked (collide.dask's workers, over their rows of a file the
//   client loaded).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstdint>
#include <cstdio>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "bindings.hpp"
#include "collide/io/generate.hpp"
#include "collide/io/scene.hpp"
#include "collide/io/scene_io.hpp"
#include "collide/io/scene_values.hpp"
#include "scene.hpp"

namespace collide::python {

Bodies::Bodies(const py::object& inv_mass_in, const py::object& inv_inertia_in, const py::object& q_in,
               const py::object& p_in, const py::object& v_in, const py::object& w_in) {
  const std::string owner = "bodies";
  dtype = scene_dtype(
      owner,
      {{"inv_mass", inv_mass_in}, {"inv_inertia", inv_inertia_in}, {"q", q_in}, {"p", p_in}, {"v", v_in}, {"w", w_in}});
  const py::dtype dt = numpy_dtype(dtype);
  const char* dn = dtype_name(dtype);
  inv_mass = checked_array(owner, "inv_mass", inv_mass_in, dt, dn, 0, false);
  inv_inertia = checked_array(owner, "inv_inertia", inv_inertia_in, dt, dn, 3, false);
  q = checked_array(owner, "q", q_in, dt, dn, 4, false);
  p = checked_array(owner, "p", p_in, dt, dn, 3, false);
  v = checked_array(owner, "v", v_in, dt, dn, 3, true);
  w = checked_array(owner, "w", w_in, dt, dn, 3, true);
  count = length(inv_mass);
  for (const auto& [name, a] : {std::pair<const char*, const py::array*>{"inv_inertia", &inv_inertia},
                                {"q", &q},
                                {"p", &p},
                                {"v", &v},
                                {"w", &w}}) {
    require_length(owner, name, *a, count, "inv_mass");
  }
  if (count > std::numeric_limits<BodyIndex>::max()) throw py::value_error("bodies: more than 2^32 - 1 bodies");
  // The solve writes v and w: neither may share memory with another array.
  std::vector<ArrayBytes> arrays;
  add_bytes(arrays, *this);
  require_disjoint(arrays);
}

void add_bytes(std::vector<ArrayBytes>& out, const Bodies& b) {
  add_bytes(out, "bodies", "inv_mass", b.inv_mass, false);
  add_bytes(out, "bodies", "inv_inertia", b.inv_inertia, false);
  add_bytes(out, "bodies", "q", b.q, false);
  add_bytes(out, "bodies", "p", b.p, false);
  add_bytes(out, "bodies", "v", b.v, true);
  add_bytes(out, "bodies", "w", b.w, true);
}

void add_bytes(std::vector<ArrayBytes>& out, const Contacts& c) {
  add_bytes(out, "contacts", "a", c.a, false);
  add_bytes(out, "contacts", "b", c.b, false);
  add_bytes(out, "contacts", "c", c.c, false);
  add_bytes(out, "contacts", "n", c.n, false);
  if (c.e) add_bytes(out, "contacts", "e", *c.e, false);
  if (c.mu) add_bytes(out, "contacts", "mu", *c.mu, false);
}

Contacts::Contacts(const py::object& a_in, const py::object& b_in, const py::object& c_in, const py::object& n_in,
                   const py::object& e_in, double uniform_e_in, const py::object& mu_in) {
  const std::string owner = "contacts";
  const py::dtype u32 = py::dtype::of<std::uint32_t>();
  a = checked_array(owner, "a", a_in, u32, "uint32", 0, false);
  b = checked_array(owner, "b", b_in, u32, "uint32", 0, false);
  dtype = scene_dtype(owner, {{"c", c_in}, {"n", n_in}, {"e", e_in}, {"mu", mu_in}});
  const py::dtype dt = numpy_dtype(dtype);
  const char* dn = dtype_name(dtype);
  c = checked_array(owner, "c", c_in, dt, dn, 3, false);
  n = checked_array(owner, "n", n_in, dt, dn, 3, false);
  if (!e_in.is_none()) e = checked_array(owner, "e", e_in, dt, dn, 0, false);
  if (!mu_in.is_none()) mu = checked_array(owner, "mu", mu_in, dt, dn, 0, false);
  uniform_e = uniform_e_in;
  count = length(a);
  require_length(owner, "b", b, count, "a");
  require_length(owner, "c", c, count, "a");
  require_length(owner, "n", n, count, "a");
  if (e) require_length(owner, "e", *e, count, "a");
  if (mu) require_length(owner, "mu", *mu, count, "a");
}

std::optional<Model> parse_model(const std::string& s) {
  if (s == "auto") return std::nullopt;
  if (s == "rigid") return Model::rigid;
  if (s == "sphere") return Model::sphere;
  if (s == "particle") return Model::particle;
  throw py::value_error("model must be 'auto', 'rigid', 'sphere' or 'particle', got '" + s + "'");
}

Model parse_named_model(const std::string& s, const char* who) {
  const std::optional<Model> m = parse_model(s);
  if (!m) throw py::value_error(std::string(who) + " needs a model: 'rigid', 'sphere' or 'particle'");
  return *m;
}

namespace {

py::tuple generate_py(const std::string& kind, const py::object& n_in, std::uint64_t seed, const std::string& model,
                      bool friction, bool shuffle, const py::object& dtype_in) {
  const Dtype d = parse_dtype(dtype_in);
  const std::size_t most = max_scene_count(kind);
  if (most == 0) throw py::value_error("kind must be 'pairs', 'debris', 'pile' or 'chain', got '" + kind + "'");
  // The range of `collide gen --<kind> N` (for a pile, N boxes per side).
  const auto n = static_cast<std::size_t>(
      integer_argument(n_in, kind == "pile" ? "n (boxes per side of a pile)" : "n", 1, static_cast<long long>(most)));
  if (shuffle && kind != "pile") throw py::value_error("shuffle is for kind 'pile' only");
  GenerateOptions o;
  o.seed = seed;
  o.friction = friction;
  o.shuffle = shuffle;
  o.model = parse_named_model(model, "generate");
  return with_dtype(d, [&](auto tag) {
    using T = decltype(tag);
    Scene<T> s;
    {
      py::gil_scoped_release release;
      s = kind == "pairs"    ? generate_pairs<T>(n, o)
          : kind == "debris" ? generate_debris<T>(n, o)
          : kind == "pile"   ? generate_pile<T>(n, o)
                             : generate_chain<T>(n, o);
    }
    return scene_objects<T>(std::as_const(s.bodies).view(), s.contacts.view(), d);
  });
}

/// Bodies from physical units: mass (inf = immovable), principal moments
/// (inf = no rotation about that axis), any non-zero quaternion (stored as
/// given: the law normalises it). The arrays hold `dtype`, or float64 scene
/// values for a float32 result (rounded as the readers round them).
py::object from_physical_py(const py::object& m_in, const py::object& inertia_in, const py::object& q_in,
                            const py::object& p_in, const py::object& v_in, const py::object& w_in,
                            const py::object& dtype_in) {
  const Dtype d = parse_dtype(dtype_in);
  const bool wide = d == Dtype::f32 && py::isinstance<py::array>(m_in) &&
                    py::reinterpret_borrow<py::array>(m_in).dtype().equal(py::dtype::of<double>());
  const Dtype given = wide ? Dtype::f64 : d;
  const py::dtype dt = numpy_dtype(d);
  const py::dtype gdt = numpy_dtype(given);
  const char* gdn = dtype_name(given);
  const std::string owner = "from_physical";
  const py::array m = checked_array(owner, "m", m_in, gdt, gdn, 0, false);
  const py::array I = checked_array(owner, "inertia", inertia_in, gdt, gdn, 3, false);
  const py::array q = checked_array(owner, "q", q_in, gdt, gdn, 4, false);
  const py::array p = checked_array(owner, "p", p_in, gdt, gdn, 3, false);
  const py::array v = checked_array(owner, "v", v_in, gdt, gdn, 3, false);
  const py::array w = checked_array(owner, "w", w_in, gdt, gdn, 3, false);
  const std::size_t n = length(m);
  for (const auto& [name, a] :
       {std::pair<const char*, const py::array*>{"inertia", &I}, {"q", &q}, {"p", &p}, {"v", &v}, {"w", &w}}) {
    require_length(owner, name, *a, n, "m");
  }
  // The arrays are the columns of a bodies file (kBodyColumns order).
  const auto columns_over = [&](auto tag) {
    using U = decltype(tag);
    BodyColumns<U> c;
    c.count = n;
    c.column = {data<U>(m),   row<U>(I, 0), row<U>(I, 1), row<U>(I, 2), row<U>(q, 0), row<U>(q, 1),
                row<U>(q, 2), row<U>(q, 3), row<U>(p, 0), row<U>(p, 1), row<U>(p, 2), row<U>(v, 0),
                row<U>(v, 1), row<U>(v, 2), row<U>(w, 0), row<U>(w, 1), row<U>(w, 2)};
    return c;
  };
  return with_dtype(d, [&](auto tag) {
    using T = decltype(tag);
    BodyTable<T> rounded;  // the values in T of float64 arrays for a float32 result
    BodyColumns<T> columns;
    std::optional<RowDefect> defect;
    if (wide) {
      const BodyColumns<double> scene = columns_over(double{});
      py::gil_scoped_release release;
      defect = narrow_bodies(scene, rounded);
      columns = columns_of(rounded);
    } else {
      columns = columns_over(T{});
      py::gil_scoped_release release;
      defect = first_body_defect(columns);
    }
    if (defect) {
      const std::string column(defect->defect.column);
      throw py::value_error(owner + ": body " + std::to_string(defect->row) + ", column '" + column +
                            "': " + defect->defect.reason);
    }
    const auto [inv_mass, inv_inertia] = inverse_arrays(columns, d);
    const auto copy = [&](std::size_t first, std::size_t rows) {
      return copy_rows<T>(dt, columns.column.data() + first, rows, n);
    };
    return py::cast(Bodies(inv_mass, inv_inertia, copy(4, 4), copy(8, 3), copy(11, 3), copy(14, 3)));
  });
}

/// Scene values (a float64 array) rounded into `out` (a float32 array of the
/// same shape, or float64: a copy) as the readers round them; ValueError
/// naming the first element beyond float, with the readers' reason. For
/// rows a caller reads itself from a file the readers have checked
/// (collide.dask's workers).
void scene_values_py(const py::object& values_in, const py::object& out_in) {
  const std::string owner = "scene_values";
  const py::array values = checked_array(owner, "values", values_in, py::dtype::of<double>(), "float64", 0, false);
  const Dtype d = scene_dtype("scene_values.out", out_in);
  const py::array out = checked_array(owner, "out", out_in, numpy_dtype(d), dtype_name(d), 0, true);
  const std::size_t n = length(values);
  require_length(owner, "out", out, n, "values");
  with_dtype(d, [&](auto tag) {
    using T = decltype(tag);
    std::size_t bad = n;
    {
      py::gil_scoped_release release;
      bad = narrow_column(values.data(), n, data<T>(out));
    }
    if (bad < n) {
      throw py::value_error(owner + ": element " + std::to_string(bad) + ": " +
                            out_of_range_reason<T>(data<double>(values)[bad]));
    }
  });
}

/// 1/m and 1/I as the readers compute them (inverses_of), for columns that
/// have passed the rules: (inv_mass (N,), inv_inertia (3, N)). Any value is
/// safe (a division, no index), but only checked columns give the scene's
/// meaning.
py::tuple inverses_py(const py::object& m_in, const py::object& inertia_in) {
  const std::string owner = "inverses";
  const Dtype d = scene_dtype("inverses.m", m_in);
  const py::dtype dt = numpy_dtype(d);
  const char* dn = dtype_name(d);
  const py::array m = checked_array(owner, "m", m_in, dt, dn, 0, false);
  const py::array I = checked_array(owner, "inertia", inertia_in, dt, dn, 3, false);
  const std::size_t n = length(m);
  require_length(owner, "inertia", I, n, "m");
  return with_dtype(d, [&](auto tag) {
    using T = decltype(tag);
    BodyColumns<T> columns;  // only m and I are read
    columns.count = n;
    columns.column[0] = data<T>(m);
    for (py::ssize_t k = 0; k < 3; ++k) columns.column[static_cast<std::size_t>(1 + k)] = row<T>(I, k);
    const auto [inv_mass, inv_inertia] = inverse_arrays(columns, d);
    return py::make_tuple(inv_mass, inv_inertia);
  });
}

/// model "auto" of a solve: the cheapest model that fits the scene, after
/// validate() (check=false: the caller has validated these very arrays, as
/// collide.load does; indices are checked either way, the choice reads the
/// bodies of every contact).
std::string choose_model_py(const Bodies& bodies, const Contacts& contacts, bool check) {
  require_same_dtype(bodies, contacts);
  return with_dtype(bodies.dtype, [&](auto tag) {
    using T = decltype(tag);
    if (check) {
      validate_or_throw<T>(bodies, contacts);
    } else if (const Validation v =
                   validate_indices(contacts.view<T>().a, contacts.view<T>().b, contacts.count, bodies.count);
               !v) {
      throw py::value_error(v.message);
    }
    return std::string(to_string(choose_model(bodies.view<T>(), contacts.view<T>())));
  });
}

/// Why `model` does not fit the scene, or "".
std::string model_misfit_py(const Bodies& bodies, const Contacts& contacts, const std::string& model) {
  require_same_dtype(bodies, contacts);
  const Model mm = parse_named_model(model, "model_misfit");
  return with_dtype(bodies.dtype, [&](auto tag) {
    using T = decltype(tag);
    return model_misfit(mm, bodies.view<T>(), contacts.view<T>());
  });
}

}  // namespace

void register_scene(py::module_& m) {
  py::class_<Bodies>(m, "Bodies")
      .def(py::init<const py::object&, const py::object&, const py::object&, const py::object&, const py::object&,
                    const py::object&>(),
           py::arg("inv_mass"), py::arg("inv_inertia"), py::arg("q"), py::arg("p"), py::arg("v"), py::arg("w"))
      .def_readonly("inv_mass", &Bodies::inv_mass)
      .def_readonly("inv_inertia", &Bodies::inv_inertia)
      .def_readonly("q", &Bodies::q)
      .def_readonly("p", &Bodies::p)
      .def_readonly("v", &Bodies::v)
      .def_readonly("w", &Bodies::w)
      .def_property_readonly("dtype", [](const Bodies& b) { return numpy_dtype(b.dtype); })
      .def("__len__", [](const Bodies& b) { return b.count; })
      .def("__repr__", [](const Bodies& b) {
        return "collide.Bodies(" + std::to_string(b.count) + " bodies, " + dtype_name(b.dtype) +
               ": inv_mass (N,), inv_inertia, p, v, w (3, N), q (4, N))";
      });

  py::class_<Contacts>(m, "Contacts")
      .def(py::init<const py::object&, const py::object&, const py::object&, const py::object&, const py::object&,
                    double, const py::object&>(),
           py::arg("a"), py::arg("b"), py::arg("c"), py::arg("n"), py::arg("e") = py::none(),
           py::arg("uniform_e") = 1.0, py::arg("mu") = py::none())
      .def_readonly("a", &Contacts::a)
      .def_readonly("b", &Contacts::b)
      .def_readonly("c", &Contacts::c)
      .def_readonly("n", &Contacts::n)
      .def_property_readonly("e", [](const Contacts& c) { return c.e ? py::object(*c.e) : py::none(); })
      .def_property_readonly("mu", [](const Contacts& c) { return c.mu ? py::object(*c.mu) : py::none(); })
      .def_readonly("uniform_e", &Contacts::uniform_e)
      .def_property_readonly("dtype", [](const Contacts& c) { return numpy_dtype(c.dtype); })
      .def("__len__", [](const Contacts& c) { return c.count; })
      .def("__repr__", [](const Contacts& c) {
        std::string e = "e per contact";
        if (!c.e) {
          char uniform[48];
          std::snprintf(uniform, sizeof uniform, "uniform_e %.17g", c.uniform_e);
          e = uniform;
        }
        return "collide.Contacts(" + std::to_string(c.count) + " contacts, " + dtype_name(c.dtype) + ", " + e + ", " +
               (c.mu ? "mu per contact" : "frictionless") + ")";
      });

  m.def("generate", &generate_py, py::arg("kind"), py::arg("n"), py::kw_only(), py::arg("seed") = 1,
        py::arg("model") = "rigid", py::arg("friction") = false, py::arg("shuffle") = false,
        py::arg("dtype") = py::none());
  m.def("from_physical", &from_physical_py, py::arg("m"), py::arg("inertia"), py::arg("q"), py::arg("p"), py::arg("v"),
        py::arg("w"), py::arg("dtype"));
  m.def("inverses", &inverses_py, py::arg("m"), py::arg("inertia"));
  m.def("scene_values", &scene_values_py, py::arg("values"), py::arg("out"));
  m.def("choose_model", &choose_model_py, py::arg("bodies"), py::arg("contacts"), py::arg("check") = true);
  m.def("model_misfit", &model_misfit_py, py::arg("bodies"), py::arg("contacts"), py::arg("model"));
}

}  // namespace collide::python
