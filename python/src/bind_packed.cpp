// python/src/bind_packed.cpp - collide.PackedBodies: the record dtypes, the
// checks of a record array and of the inverse masses beside rigid records,
// the field views, and exact copies between records and Bodies.
//
// Design notes
// ------------
// * The NumPy record dtype of each model is built from the C++ offsets
//   (offsetof on collide/packed.hpp's records) and sizeof, padding
//   included, so Python and C++ can never disagree about a field.
// * Every property is defined here: the fields (v, w, p, q, inv_inertia,
//   inv_mass) are views of the records through their structured form, and
//   rigid records' inv_mass is the very array beside them.
// * Packing and unpacking are the library's pack(), unpack() and
//   unpack_velocities() on the views, without the GIL; what a record does
//   not hold is, in new Bodies, that of the same body in the rigid model.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "bindings.hpp"
#include "packed_bodies.hpp"

namespace collide::python {
namespace {

constexpr std::array<Model, 3> kModels = {Model::rigid, Model::sphere, Model::particle};

/// f(Record{}) for the record type of model m with values of type T.
template <class T, class F>
auto with_record_type(Model m, F&& f) {
  switch (m) {
    case Model::sphere:
      return f(PackedSphere<T>{});
    case Model::particle:
      return f(PackedParticle<T>{});
    case Model::rigid:
      break;
  }
  return f(PackedRigid<T>{});
}
template <class F>
auto with_record_type(Model m, Dtype d, F&& f) {
  return with_dtype(d, [&](auto tag) { return with_record_type<decltype(tag)>(m, f); });
}
std::size_t record_size(Model m, Dtype d) {
  return with_record_type(m, d, [](const auto& r) { return sizeof(r); });
}
std::size_t record_align(Model m, Dtype d) {
  return with_record_type(m, d, [](const auto& r) { return alignof(std::decay_t<decltype(r)>); });
}

/// One field of a record: name, byte offset, values (1: a scalar field).
struct RecordField {
  const char* name;
  std::size_t offset;
  std::size_t values;
};

template <class T>
std::vector<RecordField> record_fields(Model m) {
  using R = PackedRigid<T>;
  using S = PackedSphere<T>;
  using P = PackedParticle<T>;
  switch (m) {
    case Model::sphere:
      return {{"v", offsetof(S, v), 3},
              {"w", offsetof(S, w), 3},
              {"p", offsetof(S, p), 3},
              {"inv_mass", offsetof(S, inv_mass), 1},
              {"inv_inertia", offsetof(S, inv_inertia), 1}};
    case Model::particle:
      return {{"v", offsetof(P, v), 3}, {"inv_mass", offsetof(P, inv_mass), 1}};
    case Model::rigid:
      break;
  }
  return {{"v", offsetof(R, v), 3},
          {"w", offsetof(R, w), 3},
          {"p", offsetof(R, p), 3},
          {"q", offsetof(R, q), 4},
          {"inv_inertia", offsetof(R, inv_inertia), 3}};
}

/// The NumPy structured dtype of a record: its fields at the C++ offsets and
/// itemsize sizeof(Record), padding included.
py::dtype record_dtype(Model m, Dtype d) {
  const std::vector<RecordField> fields = d == Dtype::f32 ? record_fields<float>(m) : record_fields<double>(m);
  py::list names, formats, offsets;
  for (const RecordField& f : fields) {
    names.append(f.name);
    if (f.values == 1) {
      formats.append(numpy_dtype(d));
    } else {
      formats.append(py::make_tuple(numpy_dtype(d), py::make_tuple(f.values)));
    }
    offsets.append(f.offset);
  }
  py::dict spec;
  spec["names"] = names;
  spec["formats"] = formats;
  spec["offsets"] = offsets;
  spec["itemsize"] = record_size(m, d);
  return py::dtype::from_args(spec);
}

// ---------------------------------------------------------------------------
// Exact copies between records and Bodies.
// ---------------------------------------------------------------------------

template <class View>
struct RecordOf;
template <class R>
struct RecordOf<PackedView<R>> {
  using type = R;
};

/// The SoA view of `bodies` for the model of records R.
template <class R, class T>
auto soa_view_for(const BodyView<T>& bodies) {
  if constexpr (std::is_same_v<R, PackedSphere<T>>) {
    return sphere_view(bodies);
  } else if constexpr (std::is_same_v<R, PackedParticle<T>>) {
    return particle_view(bodies);
  } else {
    return bodies;
  }
}

void require_same_scene(const Bodies& bodies, const PackedBodies& packed) {
  if (bodies.dtype != packed.dtype) {
    throw py::type_error(std::string("bodies are ") + dtype_name(bodies.dtype) + " but the records are " +
                         dtype_name(packed.dtype));
  }
  if (bodies.count != packed.count) {
    throw py::value_error("bodies has " + std::to_string(bodies.count) + " bodies but the records " +
                          std::to_string(packed.count));
  }
}

/// f(records, soa) without the GIL, for the records' view and the SoA view
/// of `bodies` of the same model.
template <class F>
void with_both_views(const PackedBodies& packed, const Bodies& bodies, F&& f) {
  with_dtype(packed.dtype, [&](auto tag) {
    using T = decltype(tag);
    const BodyView<T> bv = bodies.view<T>();
    with_records<T>(packed, [&](const auto& records) {
      using R = typename RecordOf<std::decay_t<decltype(records)>>::type;
      const auto soa = soa_view_for<R>(bv);
      py::gil_scoped_release release;
      f(records, soa);
    });
  });
}

/// Bodies into records (an exact copy): every field the record holds.
void pack_into(const Bodies& bodies, const PackedBodies& packed) {
  require_same_scene(bodies, packed);
  // Rigid inverse masses are copied into the side array, unless it is the
  // bodies' own (library pack() leaves it then).
  if (packed.inv_mass && packed.inv_mass->data() != bodies.inv_mass.data() && !writeable(*packed.inv_mass)) {
    throw py::type_error("packed.inv_mass must be writeable to pack into it");
  }
  with_both_views(packed, bodies, [](const auto& records, const auto& soa) { pack(soa, records); });
}

/// Records into bodies (an exact copy): every field the record holds, or
/// only v and w of movable bodies.
void unpack_into(const PackedBodies& packed, const Bodies& bodies, bool velocities_only) {
  require_same_scene(bodies, packed);
  if (!velocities_only) {
    for (const auto& [name, a] : {std::pair<const char*, const py::array*>{"inv_mass", &bodies.inv_mass},
                                  {"inv_inertia", &bodies.inv_inertia},
                                  {"q", &bodies.q},
                                  {"p", &bodies.p}}) {
      if (!writeable(*a)) throw py::type_error(std::string("bodies.") + name + " must be writeable to unpack into it");
    }
  }
  with_both_views(packed, bodies, [velocities_only](const auto& records, const auto& soa) {
    if (velocities_only) {
      unpack_velocities(records, soa);
    } else {
      unpack(records, soa);
    }
  });
}

/// The collide.Bodies argument `into` of an unpack method.
const Bodies& bodies_argument(const char* method, const py::object& into) {
  if (!py::isinstance<Bodies>(into)) {
    throw py::type_error(std::string(method) + ": into must be collide.Bodies, got " + text(py::type::of(into)));
  }
  return into.cast<const Bodies&>();
}

/// packed.unpack(into=None): into `into`, or into new arrays where what the
/// record does not hold is that of the same body in the rigid model.
py::object unpack_method(const PackedBodies& packed, const py::object& into) {
  if (!into.is_none()) {
    unpack_into(packed, bodies_argument("unpack", into), false);
    return into;
  }
  const auto n = static_cast<py::ssize_t>(packed.count);
  const auto zeros = [&](std::vector<py::ssize_t> shape) {
    py::array a = new_array(packed.dtype, std::move(shape));
    std::memset(a.mutable_data(), 0, static_cast<std::size_t>(a.nbytes()));
    return a;
  };
  py::array q = zeros({4, n});
  with_dtype(packed.dtype, [&](auto tag) {
    using T = decltype(tag);
    std::fill_n(row<T>(q, 0), n, T(1));
  });
  py::object result = py::cast(Bodies(zeros({n}), zeros({3, n}), q, zeros({3, n}), zeros({3, n}), zeros({3, n})));
  const Bodies& bodies = result.cast<const Bodies&>();
  unpack_into(packed, bodies, false);
  if (packed.model == Model::sphere) {  // one moment: three equal ones
    with_dtype(packed.dtype, [&](auto tag) {
      using T = decltype(tag);
      const Vec3Array<T> ii = vec3<T>(bodies.inv_inertia);
      std::copy_n(ii.x, n, ii.y);
      std::copy_n(ii.x, n, ii.z);
    });
  }
  return result;
}

/// The records as a 1-D structured array of packed_dtype(): the records
/// themselves, or a view of the (N, k) float array.
py::object structured(const PackedBodies& b) {
  if (b.records.dtype().kind() == 'V') return b.records;
  return b.records.attr("view")(record_dtype(b.model, b.dtype)).attr("reshape")(b.count);
}

}  // namespace

// ---------------------------------------------------------------------------
// The checks of the records and of the inverse masses beside them.
// ---------------------------------------------------------------------------

PackedBodies::PackedBodies(const py::object& records_in, const std::string& model_name, const py::object& inv_mass_in) {
  const std::string what = "packed.records";
  if (!py::isinstance<py::array>(records_in)) {
    throw py::type_error(what + " must be a numpy.ndarray, got " + text(py::type::of(records_in)));
  }
  const auto a = py::reinterpret_borrow<py::array>(records_in);
  set_model(a, parse_model(model_name), model_name, !inv_mass_in.is_none());
  if ((a.flags() & py::array::c_style) == 0) throw py::type_error(what + " must be C-contiguous");
  if (!writeable(a)) throw py::type_error(what + " must be writeable: the solve updates v and w in place");
  const std::size_t align = record_align(model, dtype);
  const auto address = reinterpret_cast<std::uintptr_t>(a.data());
  if (address % align != 0) {
    throw py::type_error(what + " starts " + std::to_string(address % align) + " bytes past a multiple of " +
                         std::to_string(align) + ", the alignment of " + to_string(model) + " " + dtype_name(dtype) +
                         " records: allocate them with collide.packed_empty() or collide.pack()");
  }
  records = a;
  count = static_cast<std::size_t>(a.shape(0));
  if (count > std::numeric_limits<BodyIndex>::max()) throw py::value_error("packed: more than 2^32 - 1 bodies");
  if (model == Model::rigid) {
    set_inv_mass(inv_mass_in);
  } else if (!inv_mass_in.is_none()) {
    throw py::type_error(std::string("packed.inv_mass is given, but ") + to_string(model) +
                         " records hold their inverse masses: inv_mass= is for rigid records only");
  }
}

/// Sets the model and dtype of the records `a`: the model whose record dtype
/// (structured) or record width (columns) it has, among `requested` or all.
/// Float records of 16 values are rigid or sphere records: a given inv_mass
/// says rigid (only rigid records take one), else the caller must say
/// (TypeError): guessing sphere for rigid records would solve garbage.
void PackedBodies::set_model(const py::array& a, const std::optional<Model>& requested, const std::string& model_name,
                             bool has_inv_mass) {
  const std::string what = "packed.records";
  const std::vector<Model> candidates =
      requested ? std::vector<Model>{*requested} : std::vector<Model>(kModels.begin(), kModels.end());
  if (a.dtype().kind() == 'V') {
    for (const Dtype d : {Dtype::f32, Dtype::f64}) {
      for (const Model m : candidates) {
        if (a.dtype().equal(record_dtype(m, d))) {
          if (a.ndim() != 1) throw py::type_error(what + " has shape " + shape_text(a) + ", expected (N,) records");
          dtype = d;
          model = m;
          return;
        }
      }
    }
    throw py::type_error(what + " has dtype " + text(a.dtype()) + ", which is not " +
                         (requested ? "collide.packed_dtype('" + model_name + "', float32 or float64)"
                                    : std::string("a record dtype of collide.packed_dtype()")));
  }
  dtype = scene_dtype(what, a);
  const std::size_t t = dtype == Dtype::f32 ? sizeof(float) : sizeof(double);
  std::vector<Model> matches;
  std::vector<std::pair<std::size_t, std::string>> widths;  // values per record: the models of that width
  for (const Model m : candidates) {
    const std::size_t k = record_size(m, dtype) / t;
    if (a.ndim() == 2 && static_cast<std::size_t>(a.shape(1)) == k) matches.push_back(m);
    const auto same = std::find_if(widths.begin(), widths.end(), [&](const auto& w) { return w.first == k; });
    if (same == widths.end()) {
      widths.emplace_back(k, to_string(m));
    } else {
      same->second += std::string(" or ") + to_string(m);
    }
  }
  if (matches.empty()) {
    std::string expected;
    for (const auto& [k, names] : widths) {
      expected += (expected.empty() ? "" : " or ") + std::string("(N, ") + std::to_string(k) + ") for " + names;
    }
    throw py::type_error(what + " has shape " + shape_text(a) + ", expected " + expected + " records of " +
                         dtype_name(dtype));
  }
  if (matches.size() == 1) {
    model = matches.front();
    return;
  }
  if (has_inv_mass && std::find(matches.begin(), matches.end(), Model::rigid) != matches.end()) {
    model = Model::rigid;
    return;
  }
  std::string names;
  for (const Model m : matches) names += (names.empty() ? "" : " or ") + std::string(to_string(m));
  throw py::type_error(what + " of shape " + shape_text(a) + " and dtype " + dtype_name(dtype) + " may be " + names +
                       " records: say which with model=, or give rigid records their inv_mass=");
}

/// The rigid records' inverse masses: an (N,) array of their dtype, read in
/// place (checked like every array argument), and apart from the records
/// the solve writes.
void PackedBodies::set_inv_mass(const py::object& inv_mass_in) {
  if (inv_mass_in.is_none()) {
    throw py::type_error(std::string("packed.inv_mass is missing: rigid records hold no inverse mass, it lives "
                                     "beside them; give PackedBodies(records, inv_mass=...) a C-contiguous (N,) ") +
                         dtype_name(dtype) + " array");
  }
  const py::array m = checked_array("packed", "inv_mass", inv_mass_in, numpy_dtype(dtype), dtype_name(dtype), 0, false);
  require_length("packed", "inv_mass", m, count, "packed.records");
  inv_mass = m;
  std::vector<ArrayBytes> arrays;
  add_bytes(arrays, *this);
  require_disjoint(arrays);  // the solve writes the records while it reads the inverse masses
}

void add_bytes(std::vector<ArrayBytes>& out, const PackedBodies& b) {
  out.push_back({"packed", "records", b.records.data(), b.count * record_size(b.model, b.dtype), true});
  if (b.inv_mass) add_bytes(out, "packed", "inv_mass", *b.inv_mass, false);
}

// ---------------------------------------------------------------------------
// Registration.
// ---------------------------------------------------------------------------

void register_packed(py::module_& m) {
  py::class_<PackedBodies> cls(m, "PackedBodies");
  cls.def(py::init<const py::object&, const std::string&, const py::object&>(), py::arg("records"), py::kw_only(),
          py::arg("model") = "auto", py::arg("inv_mass") = py::none())
      .def_readonly("records", &PackedBodies::records)
      .def_property_readonly("model", [](const PackedBodies& b) { return std::string(to_string(b.model)); })
      .def_property_readonly("dtype", [](const PackedBodies& b) { return numpy_dtype(b.dtype); })
      .def_property_readonly("record_dtype", [](const PackedBodies& b) { return record_dtype(b.model, b.dtype); })
      .def("__len__", [](const PackedBodies& b) { return b.count; })
      .def("__repr__",
           [](const PackedBodies& b) {
             return "collide.PackedBodies(" + std::to_string(b.count) + " " + to_string(b.model) +
                    (b.count == 1 ? " record, " : " records, ") + dtype_name(b.dtype) + ", " +
                    std::to_string(record_size(b.model, b.dtype)) + " bytes each" +
                    (b.inv_mass ? std::string(", inv_mass (N,) beside them") : std::string()) + ")";
           })
      .def_property_readonly("structured", &structured,
                             "The records as a 1-D structured array of packed_dtype() (a view of the same memory; "
                             "rigid records have no inv_mass field: see inv_mass).")
      .def_property_readonly(
          "inv_mass",
          [](const PackedBodies& b) -> py::object {
            return b.inv_mass ? py::object(*b.inv_mass) : py::object(structured(b)["inv_mass"]);
          },
          "inverse masses (N,): for rigid records the array beside them (the one given to the constructor, "
          "itself), for sphere and particle records a view of the records")
      // The array beside rigid records, or None.
      .def_property_readonly("_inv_mass",
                             [](const PackedBodies& b) { return b.inv_mass ? py::object(*b.inv_mass) : py::none(); })
      .def("unpack", &unpack_method, py::arg("into") = py::none(),
           "The records as Bodies: an exact copy of every field the record holds (and of a rigid record's inverse "
           "mass beside it), into ``into`` (same count and dtype; its inv_mass, inv_inertia, q and p must be "
           "writeable) or into new arrays, where the fields the record does not hold are those of the same body in "
           "the rigid model: sphere records give three equal moments and q = (1, 0, 0, 0); particle records also "
           "give zero moments, p and w.")
      .def(
          "unpack_velocities",
          [](const PackedBodies& packed, const py::object& into) {
            unpack_into(packed, bodies_argument("unpack_velocities", into), true);
            return into;
          },
          py::arg("into"),
          "Copies v (and w, where the record has it) of the movable bodies into ``into`` (Bodies of the same count "
          "and dtype): what a solve changed. Returns ``into``.");
  for (const auto& [name, doc] :
       {std::pair<const char*, const char*>{"v", "linear velocities (N, 3), a view of the records"},
        {"w", "angular velocities (N, 3), a view (rigid and sphere records)"},
        {"p", "centres of mass (N, 3), a view (rigid and sphere records)"},
        {"q", "orientations (N, 4) as (w, x, y, z), a view (rigid records)"},
        {"inv_inertia", "inverse moments, (N, 3) for rigid and (N,) for sphere records, a view"}}) {
    const std::string field = name;
    cls.def_property_readonly(
        name, [field](const PackedBodies& b) { return py::object(structured(b)[field.c_str()]); }, doc);
  }

  m.def(
      "packed_dtype",
      [](const std::string& model, const py::object& dtype) {
        return record_dtype(parse_named_model(model, "packed_dtype"), parse_dtype(dtype));
      },
      py::arg("model"), py::arg("dtype"));
  m.def(
      "packed_alignment",
      [](const std::string& model, const py::object& dtype) {
        return record_align(parse_named_model(model, "packed_alignment"), parse_dtype(dtype));
      },
      py::arg("model"), py::arg("dtype"));
  m.def("pack_into", &pack_into, py::arg("bodies"), py::arg("packed"));
}

}  // namespace collide::python
