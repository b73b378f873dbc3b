// python/src/collide_module.cpp - the `collide._collide` extension: a thin
// shell over the library for NumPy arrays.
//
// Design notes
// ------------
// * Zero copy: Bodies and Contacts keep the caller's ndarrays and the solve
//   runs on SoA views of their buffers (row k of a (3, N) array is component
//   k). Only arrays that already have the right dtype, shape and C layout are
//   accepted (TypeError otherwise, naming the array): a silent conversion
//   would copy, and v and w could then not be updated in place.
// * Values are checked by the library's validate() (ValueError naming the
//   array and the first bad element) before anything is written, so bad input
//   modifies nothing. Whether a scene fits a model is model_misfit()'s.
// * check=False (Solver.solve) skips validate() and the model-fit check for
//   frame loops that validated their scene once; the indices are still
//   checked, so no index outside the arrays ever reaches the kernel: by
//   Schedule::build when the solve builds its schedule, by validate_indices()
//   beside a schedule the caller built earlier. The library's
//   std::invalid_argument (Schedule::build, Solver::solve) becomes ValueError.
// * The GIL is released around every long C++ call (solve, reference,
//   report, generate, file I/O). The ndarrays stay referenced by the Bodies
//   and Contacts objects (and the call's arguments) meanwhile.
// * Packed bodies (PackedBodies) are the caller's record array, structured
//   (packed_dtype(), built here from the C++ offsets) or (N, k) floats,
//   checked for dtype, width, contiguity and alignment (TypeError) and
//   solved in place by the library's packed overloads; values are checked by
//   validate() for packed views, so records and SoA get the same messages.
//   Rigid records hold no inverse mass: it is a second caller's array, (N,)
//   beside the records (PackedView<PackedRigid<T>>::inv_mass), checked like
//   any array argument and only read by the solve.
// * The statistics dict is collide::solve_record (collide/eval/check.hpp), the
//   record `collide solve --stats` prints, and the error per contact is
//   collide::impulse_errors_eps, what `--check` summarises.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "collide/eval/check.hpp"
#include "collide/eval/error_bound.hpp"
#include "collide/io/generate.hpp"
#include "collide/isa.hpp"
#include "collide/model.hpp"
#include "collide/packed.hpp"
#include "collide/eval/reference.hpp"
#include "report.hpp"
#include "collide/rules.hpp"
#include "collide/io/scene.hpp"
#include "collide/io/scene_io.hpp"
#include "collide/io/scene_npz.hpp"
#include "collide/schedule.hpp"
#include "collide/solve.hpp"
#include "collide/validate.hpp"

namespace py = pybind11;

namespace collide::python {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

std::string text(const py::handle& h) { return py::str(h).cast<std::string>(); }

enum class Dtype { f32, f64 };
const char* dtype_name(Dtype d) { return d == Dtype::f32 ? "float32" : "float64"; }

py::dtype numpy_dtype(Dtype d) { return d == Dtype::f32 ? py::dtype::of<float>() : py::dtype::of<double>(); }

Dtype parse_dtype(const py::object& dtype) {
  const py::dtype d = py::dtype::from_args(dtype);
  if (d.is(py::dtype::of<float>()) || d.equal(py::dtype::of<float>())) return Dtype::f32;
  if (d.equal(py::dtype::of<double>())) return Dtype::f64;
  throw py::type_error("dtype must be numpy.float32 or numpy.float64, got " + text(dtype));
}

std::string shape_text(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t k = 0; k < a.ndim(); ++k) {
    if (k > 0) s += ", ";
    s += std::to_string(a.shape(k));
  }
  return s + (a.ndim() == 1 ? ",)" : ")");
}

/// The checks of one array argument: an ndarray, of `dtype`, C-contiguous,
/// aligned, writeable when the solve writes it, of `rows` rows (0: 1-D).
/// Returns its length (the last dimension). Throws TypeError naming it.
py::array checked_array(const std::string& owner, const char* name, const py::handle& obj, const py::dtype& dtype,
                        const char* dtype_text, int rows, bool writeable) {
  const std::string what = owner + "." + name;
  if (!py::isinstance<py::array>(obj)) {
    throw py::type_error(what + " must be a numpy.ndarray, got " + text(py::type::of(obj)));
  }
  py::array a = py::reinterpret_borrow<py::array>(obj);
  if (!a.dtype().equal(dtype)) {
    throw py::type_error(what + " has dtype " + text(a.dtype()) + ", expected " + dtype_text);
  }
  const bool shape_ok = rows == 0 ? a.ndim() == 1 : (a.ndim() == 2 && a.shape(0) == rows);
  if (!shape_ok) {
    throw py::type_error(what + " has shape " + shape_text(a) + ", expected " +
                         (rows == 0 ? std::string("(N,)") : "(" + std::to_string(rows) + ", N)"));
  }
  const int flags = a.flags();
  // C-contiguous, or (for a (rows, N) array) each row contiguous with the
  // rows apart: what a scene file loaded in place gives (collide.load), its
  // columns at one stride in the mapping.
  const auto item = static_cast<py::ssize_t>(a.itemsize());
  const bool rows_contiguous = rows != 0 && a.shape(1) > 0 && a.strides(1) == item && a.strides(0) % item == 0 &&
                               a.strides(0) >= a.shape(1) * item;
  if ((flags & py::array::c_style) == 0 && !rows_contiguous) {
    throw py::type_error(what + " must be C-contiguous (numpy.ascontiguousarray makes a contiguous copy)");
  }
  if ((flags & py::detail::npy_api::NPY_ARRAY_ALIGNED_) == 0) throw py::type_error(what + " must be aligned");
  if (writeable && (flags & py::detail::npy_api::NPY_ARRAY_WRITEABLE_) == 0) {
    throw py::type_error(what + " must be writeable: the solve updates it in place");
  }
  return a;
}

std::size_t length(const py::array& a) { return static_cast<std::size_t>(a.shape(a.ndim() - 1)); }

void require_length(const std::string& owner, const char* name, const py::array& a, std::size_t n, const char* first) {
  if (length(a) != n) {
    throw py::value_error(owner + "." + name + " has " + std::to_string(length(a)) + " elements, " + first + " has " +
                          std::to_string(n));
  }
}

template <class T>
T* data(const py::array& a) {
  return static_cast<T*>(const_cast<void*>(a.data()));
}
/// Row r of a (rows, N) array (rows contiguous, checked_array).
template <class T>
T* row(const py::array& a, py::ssize_t r) {
  return reinterpret_cast<T*>(static_cast<char*>(const_cast<void*>(a.data())) + r * a.strides(0));
}
template <class T>
Vec3Array<T> vec3(const py::array& a) {
  return {row<T>(a, 0), row<T>(a, 1), row<T>(a, 2)};
}

/// The dtype of a scene, from its first floating-point array `what`.
Dtype scene_dtype(const std::string& what, const py::handle& obj) {
  if (!py::isinstance<py::array>(obj)) {
    throw py::type_error(what + " must be a numpy.ndarray, got " + text(py::type::of(obj)));
  }
  const py::dtype d = py::reinterpret_borrow<py::array>(obj).dtype();
  if (d.equal(py::dtype::of<float>())) return Dtype::f32;
  if (d.equal(py::dtype::of<double>())) return Dtype::f64;
  throw py::type_error(what + " has dtype " + text(d) + ", expected float32 or float64");
}

py::array new_array(Dtype d, std::vector<py::ssize_t> shape) { return py::array(numpy_dtype(d), std::move(shape)); }

// ---------------------------------------------------------------------------
// Bodies and contacts over the caller's arrays.
// ---------------------------------------------------------------------------

struct Bodies {
  py::array inv_mass, inv_inertia, q, p, v, w;
  Dtype dtype = Dtype::f64;
  std::size_t count = 0;

  Bodies(const py::object& inv_mass_in, const py::object& inv_inertia_in, const py::object& q_in,
         const py::object& p_in, const py::object& v_in, const py::object& w_in) {
    const std::string owner = "bodies";
    dtype = scene_dtype("bodies.inv_mass", inv_mass_in);
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
  }

  template <class T>
  BodyView<T> view() const {
    return {count,
            data<T>(inv_mass),
            vec3<T>(inv_inertia),
            {row<T>(q, 0), row<T>(q, 1), row<T>(q, 2), row<T>(q, 3)},
            vec3<T>(p),
            vec3<T>(v),
            vec3<T>(w)};
  }
};

struct Contacts {
  py::array a, b, c, n;
  std::optional<py::array> e, mu;
  double uniform_e = 1;
  Dtype dtype = Dtype::f64;
  std::size_t count = 0;

  Contacts(const py::object& a_in, const py::object& b_in, const py::object& c_in, const py::object& n_in,
           const py::object& e_in, double uniform_e_in, const py::object& mu_in) {
    const std::string owner = "contacts";
    const py::dtype u32 = py::dtype::of<std::uint32_t>();
    a = checked_array(owner, "a", a_in, u32, "uint32", 0, false);
    b = checked_array(owner, "b", b_in, u32, "uint32", 0, false);
    dtype = scene_dtype("contacts.c", c_in);
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

  template <class T>
  ContactView<T> view() const {
    ContactView<T> view;
    view.count = count;
    view.a = data<BodyIndex>(a);
    view.b = data<BodyIndex>(b);
    const Vec3Array<T> cc = vec3<T>(c), nn = vec3<T>(n);
    view.c = {cc.x, cc.y, cc.z};
    view.n = {nn.x, nn.y, nn.z};
    view.e = e ? data<T>(*e) : nullptr;
    view.uniform_e = static_cast<T>(uniform_e);
    view.mu = mu ? data<T>(*mu) : nullptr;
    return view;
  }
  py::object e_object() const { return e ? py::object(*e) : py::none(); }
  py::object mu_object() const { return mu ? py::object(*mu) : py::none(); }
};

void require_same_dtype(const Bodies& bodies, const Contacts& contacts) {
  if (bodies.dtype != contacts.dtype) {
    throw py::type_error(std::string("bodies are ") + dtype_name(bodies.dtype) + " but contacts are " +
                         dtype_name(contacts.dtype) + ": one precision per solve");
  }
}

/// The impulse output: `out` when given (checked like an input), else a new array.
py::array impulse_array(const py::object& out, Dtype dtype, std::size_t m) {
  if (out.is_none()) return new_array(dtype, {3, static_cast<py::ssize_t>(m)});
  py::array j = checked_array("solve", "out", out, numpy_dtype(dtype), dtype_name(dtype), 3, true);
  require_length("solve", "out", j, m, "contacts.a");
  return j;
}

// ---------------------------------------------------------------------------
// Options.
// ---------------------------------------------------------------------------

Path parse_path(const std::string& s) {
  if (s == "simd") return Path::simd;
  if (s == "scalar") return Path::scalar;
  throw py::value_error("path must be 'simd' or 'scalar', got '" + s + "'");
}

/// "auto" -> nullopt.
std::optional<Model> parse_model(const std::string& s) {
  if (s == "auto") return std::nullopt;
  if (s == "rigid") return Model::rigid;
  if (s == "sphere") return Model::sphere;
  if (s == "particle") return Model::particle;
  throw py::value_error("model must be 'auto', 'rigid', 'sphere' or 'particle', got '" + s + "'");
}

SolverOptions solver_options(const std::string& path, int threads, const py::object& isa, const std::string& accuracy) {
  SolverOptions o;
  o.path = parse_path(path);
  if (threads < 0 || threads > 4096) throw py::value_error("threads must be from 0 (all) to 4096");
  o.threads = threads;
  try {
    if (!isa.is_none()) o.isa = parse_isa(isa.cast<std::string>());
    o.accuracy = parse_accuracy(accuracy);
  } catch (const std::invalid_argument& e) {
    throw py::value_error(e.what());
  } catch (const py::cast_error&) {
    throw py::type_error("isa must be a string or None");
  }
  return o;
}

// ---------------------------------------------------------------------------
// Packed bodies over the caller's records (collide/packed.hpp).
// ---------------------------------------------------------------------------

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
  return d == Dtype::f32 ? with_record_type<float>(m, f) : with_record_type<double>(m, f);
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

constexpr std::array<Model, 3> kModels = {Model::rigid, Model::sphere, Model::particle};

/// N packed bodies over the caller's records, with no copy: a 1-D array of
/// the record dtype (packed_dtype()), or a C-contiguous (N, k) float array
/// whose rows are the records (k values of T per record, padding included).
/// The record type is the model. v and w are updated in place. Rigid records
/// hold no inverse mass (collide/packed.hpp): theirs is the caller's (N,)
/// array `inv_mass`, beside them, which the solve only reads.
struct PackedBodies {
  py::array records;
  std::optional<py::array> inv_mass;  ///< rigid records only
  Model model = Model::rigid;
  Dtype dtype = Dtype::f32;
  std::size_t count = 0;

  PackedBodies(const py::object& records_in, const std::string& model_name, const py::object& inv_mass_in) {
    const std::string what = "packed.records";
    if (!py::isinstance<py::array>(records_in)) {
      throw py::type_error(what + " must be a numpy.ndarray, got " + text(py::type::of(records_in)));
    }
    const auto a = py::reinterpret_borrow<py::array>(records_in);
    set_model(a, parse_model(model_name), model_name, !inv_mass_in.is_none());
    const int flags = a.flags();
    if ((flags & py::array::c_style) == 0) throw py::type_error(what + " must be C-contiguous");
    if ((flags & py::detail::npy_api::NPY_ARRAY_WRITEABLE_) == 0) {
      throw py::type_error(what + " must be writeable: the solve updates v and w in place");
    }
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

  /// Sets the model and dtype of the records `a`: the model whose record
  /// dtype (structured) or record width (columns) it has, among `requested`
  /// or all. Float records of 16 values are rigid or sphere records: a given
  /// inv_mass says rigid (only rigid records take one), else the caller
  /// must say (TypeError): guessing sphere for rigid records would solve
  /// garbage.
  void set_model(const py::array& a, const std::optional<Model>& requested, const std::string& model_name,
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

  /// The rigid records' inverse masses: an (N,) array of their dtype, read
  /// in place (checked like every array argument), and apart from the
  /// records the solve writes.
  void set_inv_mass(const py::object& inv_mass_in) {
    if (inv_mass_in.is_none()) {
      throw py::type_error(std::string("packed.inv_mass is missing: rigid records hold no inverse mass, it lives "
                                       "beside them; give PackedBodies(records, inv_mass=...) a C-contiguous (N,) ") +
                           dtype_name(dtype) + " array");
    }
    const py::array m =
        checked_array("packed", "inv_mass", inv_mass_in, numpy_dtype(dtype), dtype_name(dtype), 0, false);
    require_length("packed", "inv_mass", m, count, "packed.records");
    const auto r0 = reinterpret_cast<std::uintptr_t>(records.data());
    const auto m0 = reinterpret_cast<std::uintptr_t>(m.data());
    const std::size_t t = dtype == Dtype::f32 ? sizeof(float) : sizeof(double);
    if (count != 0 && m0 < r0 + count * record_size(model, dtype) && r0 < m0 + count * t) {
      throw py::value_error(
          "packed.inv_mass overlaps packed.records: the solve writes the records while it reads "
          "the inverse masses");
    }
    inv_mass = m;
  }

  template <class Record>
  PackedView<Record> view() const {
    using T = typename PackedValue<Record>::type;
    PackedView<Record> v;
    v.count = count;
    v.bodies = data<Record>(records);
    if constexpr (std::is_same_v<Record, PackedRigid<T>>) v.inv_mass = data<T>(*inv_mass);
    return v;
  }

  /// The inverse masses beside rigid records; None for sphere and particle
  /// records, which hold theirs.
  [[nodiscard]] py::object inv_mass_object() const { return inv_mass ? py::object(*inv_mass) : py::none(); }
};

template <class View>
struct RecordOf;
template <class R>
struct RecordOf<PackedView<R>> {
  using type = R;
};

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

/// Bodies into records (an exact copy): every field the record holds.
void pack_into(const Bodies& bodies, const PackedBodies& packed) {
  require_same_scene(bodies, packed);
  // Rigid inverse masses are copied into the side array, unless it is the
  // bodies' own (library pack() leaves it then).
  if (packed.inv_mass && packed.inv_mass->data() != bodies.inv_mass.data() &&
      (packed.inv_mass->flags() & py::detail::npy_api::NPY_ARRAY_WRITEABLE_) == 0) {
    throw py::type_error("packed.inv_mass must be writeable to pack into it");
  }
  const auto run = [&](auto tag) {
    using T = decltype(tag);
    const BodyView<T> bv = bodies.view<T>();
    with_records<T>(packed, [&](const auto& records) {
      using R = typename RecordOf<std::decay_t<decltype(records)>>::type;
      const auto from = soa_view_for<R>(bv);
      py::gil_scoped_release release;
      pack(from, records);
    });
  };
  packed.dtype == Dtype::f32 ? run(float{}) : run(double{});
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
      if ((a->flags() & py::detail::npy_api::NPY_ARRAY_WRITEABLE_) == 0) {
        throw py::type_error(std::string("bodies.") + name + " must be writeable to unpack into it");
      }
    }
  }
  const auto run = [&](auto tag) {
    using T = decltype(tag);
    const BodyView<T> bv = bodies.view<T>();
    with_records<T>(packed, [&](const auto& records) {
      using R = typename RecordOf<std::decay_t<decltype(records)>>::type;
      const auto to = soa_view_for<R>(bv);
      py::gil_scoped_release release;
      if (velocities_only) {
        unpack_velocities(records, to);
      } else {
        unpack(records, to);
      }
    });
  };
  packed.dtype == Dtype::f32 ? run(float{}) : run(double{});
}

void require_same_dtype(const PackedBodies& bodies, const Contacts& contacts) {
  if (bodies.dtype != contacts.dtype) {
    throw py::type_error(std::string("bodies are ") + dtype_name(bodies.dtype) + " but contacts are " +
                         dtype_name(contacts.dtype) + ": one precision per solve");
  }
}

// ---------------------------------------------------------------------------
// Schedule and solver.
// ---------------------------------------------------------------------------

// The steps of a solve for each kind of bodies: SoA (Bodies) or packed.

/// The schedule reads only the inverse masses (immovable bodies do not
/// conflict); packed records give them in place (rigid ones beside them).
template <class T>
void build_schedule(Schedule& schedule, const ContactView<T>& cv, const Bodies& b) {
  schedule.build(cv, b.view<T>());
}
template <class T>
void build_schedule(Schedule& schedule, const ContactView<T>& cv, const PackedBodies& b) {
  with_records<T>(b, [&](const auto& records) { schedule.build(cv, records); });
}

template <class T>
Validation validate_values(const Bodies& b, const ContactView<T>& cv, const ImpulseView<T>& jv) {
  return validate(b.view<T>(), cv, jv);
}
template <class T>
Validation validate_values(const PackedBodies& b, const ContactView<T>& cv, const ImpulseView<T>& jv) {
  return with_records<T>(b, [&](const auto& records) { return validate(records, cv, jv); });
}

/// The model of a solve of SoA bodies: the requested one (which must fit
/// when `check`), else the cheapest that fits.
template <class T>
Model solve_model(const Bodies& b, const ContactView<T>& cv, const std::optional<Model>& requested, bool check) {
  const BodyView<T> bv = b.view<T>();
  if (!requested) return choose_model(bv, cv);
  const std::string misfit = check ? model_misfit(*requested, bv, cv) : std::string();
  if (!misfit.empty()) {
    throw py::value_error(std::string("model '") + to_string(*requested) + "' does not fit the scene: " + misfit);
  }
  return *requested;
}
/// Packed records: the record type is the model.
template <class T>
Model solve_model(const PackedBodies& b, const ContactView<T>&, const std::optional<Model>& requested, bool) {
  if (requested && *requested != b.model) {
    throw py::value_error(std::string("model '") + to_string(*requested) + "' does not match the records: they are " +
                          to_string(b.model) + " records, and the record type is the model");
  }
  return b.model;
}

template <class T>
SolveStats run_solve(const Solver& solver, Model model, const Bodies& b, const ContactView<T>& cv,
                     const ImpulseView<T>& jv, const Schedule& schedule) {
  return solver.solve(model, b.view<T>(), cv, jv, schedule);
}
template <class T>
SolveStats run_solve(const Solver& solver, Model, const PackedBodies& b, const ContactView<T>& cv,
                     const ImpulseView<T>& jv, const Schedule& schedule) {
  return with_records<T>(b, [&](const auto& records) { return solver.solve(records, cv, jv, schedule); });
}

template <class T, class B>
void validate_or_throw(const B& bodies, const Contacts& contacts, const ImpulseView<T>& j) {
  if (const Validation v = validate_values<T>(bodies, contacts.view<T>(), j); !v) throw py::value_error(v.message);
}

/// A schedule built for one set of contacts and bodies; reusable while the
/// indices and inverse masses do not change (a frame loop over velocities).
struct PySchedule {
  Schedule schedule;
  std::size_t contacts = 0, bodies = 0;
  double build_seconds = 0;

  /// Schedule::build's std::invalid_argument (a bad index, named) becomes
  /// ValueError.
  template <class T, class B>
  void build(const B& b, const Contacts& c) {
    const ContactView<T> cv = c.view<T>();
    const auto t0 = Clock::now();
    try {
      py::gil_scoped_release release;
      build_schedule<T>(schedule, cv, b);
    } catch (const std::invalid_argument& e) {
      throw py::value_error(e.what());
    }
    build_seconds = seconds_since(t0);
    contacts = c.count;
    bodies = b.count;
  }

  /// A schedule over validated input (it reads the indices).
  template <class B>
  static std::unique_ptr<PySchedule> make(const B& bodies, const Contacts& contacts) {
    require_same_dtype(bodies, contacts);
    auto s = std::make_unique<PySchedule>();
    const auto run = [&](auto tag) {
      using T = decltype(tag);
      ImpulseBuffer<T> scratch(contacts.count);
      validate_or_throw<T>(bodies, contacts, scratch.view());
      s->build<T>(bodies, contacts);
    };
    bodies.dtype == Dtype::f32 ? run(float{}) : run(double{});
    return s;
  }
};

py::dict to_dict(const StatRecord& record) {
  py::dict d;
  for (const auto& entry : record) {
    // Not a structured binding: clang 14 cannot capture one in the lambda.
    const std::string& key = entry.first;
    std::visit([&](const auto& x) { d[py::str(key)] = py::cast(x); }, entry.second);
  }
  return d;
}

struct PySolver {
  std::unique_ptr<Solver> solver;

  PySolver(const std::string& path, int threads, const py::object& isa, const std::string& accuracy)
      : solver(std::make_unique<Solver>(solver_options(path, threads, isa, accuracy))) {}

  /// Everything is checked before anything is written: layouts (by the
  /// Bodies/Contacts/PackedBodies constructors and impulse_array), values
  /// (validate(), or only the indices when !check), the model and the
  /// schedule's size.
  template <class T, class B>
  py::tuple solve_t(const B& bodies, const Contacts& contacts, const std::string& model_name, PySchedule* schedule,
                    const py::object& out, bool check, bool impacts) {
    const std::optional<Model> requested = parse_model(model_name);
    py::array j = impulse_array(out, bodies.dtype, contacts.count);
    T* jp = data<T>(j);
    const ImpulseView<T> jv{contacts.count, {jp, jp + contacts.count, jp + 2 * contacts.count}};
    const ContactView<T> cv = contacts.view<T>();
    // Unchecked values are the caller's word; indices never are (memory
    // safety). A schedule built here checks every index in its own pass
    // (Schedule::build throws std::invalid_argument, a ValueError here); a
    // schedule built earlier vouches only for the indices it saw then, so
    // the indices are checked again beside it.
    if (check) {
      if (const Validation v = validate_values<T>(bodies, cv, jv); !v) throw py::value_error(v.message);
    } else if (schedule != nullptr) {
      if (const Validation v = validate_indices(cv.a, cv.b, cv.count, bodies.count); !v) {
        throw py::value_error(v.message);
      }
    }
    PySchedule own;
    if (schedule == nullptr) {
      own.build<T>(bodies, contacts);  // before the model choice, which reads the bodies of every contact
      schedule = &own;
    } else if (schedule->contacts != contacts.count || schedule->bodies != bodies.count) {
      throw py::value_error("schedule was built for " + std::to_string(schedule->contacts) + " contacts and " +
                            std::to_string(schedule->bodies) + " bodies, not " + std::to_string(contacts.count) +
                            " and " + std::to_string(bodies.count));
    }
    const Model model = solve_model<T>(bodies, cv, requested, check);
    SolveStats stats;
    double kernel_seconds = 0;
    try {
      py::gil_scoped_release release;
      const auto t0 = Clock::now();
      stats = run_solve<T>(*solver, model, bodies, cv, jv, schedule->schedule);
      kernel_seconds = seconds_since(t0);
    } catch (const std::invalid_argument& e) {  // Solver::solve's checks of counts and arrays
      throw py::value_error(e.what());
    }
    // impacts=False: no pass over J (at a million contacts it costs 5-10% of
    // a particle solve); the record is built over no impulses and the key
    // set to None.
    const ImpulseView<const T> jc{impacts ? jv.count : 0, {jv.j.x, jv.j.y, jv.j.z}};
    py::dict d =
        to_dict(solve_record<T>(stats, jc, bodies.count, kernel_seconds, schedule == &own ? own.build_seconds : 0.0));
    if (!impacts) d["impacts"] = py::none();
    return py::make_tuple(j, d);
  }

  template <class B>
  py::tuple solve(const B& bodies, const Contacts& contacts, const std::string& model, PySchedule* schedule,
                  const py::object& out, bool check, bool impacts) {
    require_same_dtype(bodies, contacts);
    return bodies.dtype == Dtype::f32 ? solve_t<float>(bodies, contacts, model, schedule, out, check, impacts)
                                      : solve_t<double>(bodies, contacts, model, schedule, out, check, impacts);
  }
};

// ---------------------------------------------------------------------------
// The reference and the error measure.
// ---------------------------------------------------------------------------

/// reference_solve<long double> on an exact copy of the inputs: the caller's
/// bodies are not modified.
struct Reference {
  ImpulseBuffer<long double> impulses;
  std::vector<ReferenceContact<long double>> diagnostics;
  BodyBuffer<long double> after;
  Dtype dtype = Dtype::f64;

  py::array j_array() const {
    return ld_rows(impulses.view().j.x, impulses.view().j.y, impulses.view().j.z, impulses.size());
  }
  py::array vec_array(bool angular) const {
    const BodyView<const long double> b = after.view();
    const Vec3Array<const long double> x = angular ? b.w : b.v;
    return ld_rows(x.x, x.y, x.z, b.count);
  }
  py::array diag_array(long double ReferenceContact<long double>::*field) const {
    py::array_t<double> out(static_cast<py::ssize_t>(diagnostics.size()));
    double* o = out.mutable_data();
    for (std::size_t k = 0; k < diagnostics.size(); ++k) o[k] = static_cast<double>(diagnostics[k].*field);
    return out;
  }
  static py::array ld_rows(const long double* x, const long double* y, const long double* z, std::size_t n) {
    py::array_t<double> out({py::ssize_t{3}, static_cast<py::ssize_t>(n)});
    double* o = out.mutable_data();
    for (std::size_t k = 0; k < n; ++k) {
      o[k] = static_cast<double>(x[k]);
      o[n + k] = static_cast<double>(y[k]);
      o[2 * n + k] = static_cast<double>(z[k]);
    }
    return out;
  }
};

template <class T>
std::shared_ptr<Reference> reference_t(const Bodies& bodies, const Contacts& contacts) {
  const ImpulseView<T> none{contacts.count, {}};
  auto r = std::make_shared<Reference>();
  r->dtype = bodies.dtype;
  // validate() needs impulse storage of the right size: check the inputs with
  // a scratch buffer.
  ImpulseBuffer<T> scratch(contacts.count);
  validate_or_throw<T>(bodies, contacts, scratch.view());
  const BodyView<T> bv = bodies.view<T>();
  const ContactView<T> cv = contacts.view<T>();
  {
    py::gil_scoped_release release;
    r->after = convert_bodies<long double>(const_view(bv));
    const ContactBuffer<long double> lc = convert_contacts<long double>(cv);
    r->impulses.resize(contacts.count);
    r->diagnostics.resize(contacts.count);
    reference_solve<long double>(r->after.view(), lc.view(), r->impulses.view(), r->diagnostics.data());
  }
  (void)none;
  return r;
}

std::shared_ptr<Reference> reference_solve_py(const Bodies& bodies, const Contacts& contacts) {
  require_same_dtype(bodies, contacts);
  return bodies.dtype == Dtype::f32 ? reference_t<float>(bodies, contacts) : reference_t<double>(bodies, contacts);
}

template <class T>
py::array impulse_error_t(const py::array& j, const Reference& ref) {
  const std::size_t m = length(j);
  const T* p = data<T>(j);
  const ImpulseView<const T> jv{m, {p, p + m, p + 2 * m}};
  const ImpulseView<const long double> rv = ref.impulses.view();
  const std::vector<double> errors = impulse_errors_eps<T>(jv, rv, ref.diagnostics);
  py::array_t<double> out(static_cast<py::ssize_t>(m));
  std::copy(errors.begin(), errors.end(), out.mutable_data());
  return out;
}

py::array impulse_error_py(const py::object& j_in, const Reference& ref) {
  const Dtype dtype = scene_dtype("impulse_error.J", j_in);
  const py::array j = checked_array("impulse_error", "J", j_in, numpy_dtype(dtype), "float32 or float64", 3, false);
  require_length("impulse_error", "J", j, ref.impulses.size(), "the reference");
  return dtype == Dtype::f32 ? impulse_error_t<float>(j, ref) : impulse_error_t<double>(j, ref);
}

// ---------------------------------------------------------------------------
// Scenes: generated, read, written; bodies from physical units.
// ---------------------------------------------------------------------------

template <class T>
py::array copy_rows(Dtype d, std::initializer_list<const T*> rows, std::size_t n) {
  const bool one = rows.size() == 1;
  py::array a = one ? new_array(d, {static_cast<py::ssize_t>(n)})
                    : new_array(d, {static_cast<py::ssize_t>(rows.size()), static_cast<py::ssize_t>(n)});
  T* o = data<T>(a);
  for (const T* r : rows) {
    std::copy(r, r + n, o);
    o += n;
  }
  return a;
}

template <class T>
py::tuple to_python(const BodyView<const T>& b, const ContactView<T>& c, Dtype d) {
  const std::size_t n = b.count, m = c.count;
  py::object bodies = py::cast(
      Bodies(copy_rows<T>(d, {b.inv_mass}, n), copy_rows<T>(d, {b.inv_inertia.x, b.inv_inertia.y, b.inv_inertia.z}, n),
             copy_rows<T>(d, {b.q.w, b.q.x, b.q.y, b.q.z}, n), copy_rows<T>(d, {b.p.x, b.p.y, b.p.z}, n),
             copy_rows<T>(d, {b.v.x, b.v.y, b.v.z}, n), copy_rows<T>(d, {b.w.x, b.w.y, b.w.z}, n)));
  py::array_t<std::uint32_t> a(static_cast<py::ssize_t>(m)), bb(static_cast<py::ssize_t>(m));
  std::copy(c.a, c.a + m, a.mutable_data());
  std::copy(c.b, c.b + m, bb.mutable_data());
  py::object e = c.e ? py::object(copy_rows<T>(d, {c.e}, m)) : py::none();
  py::object mu = c.mu ? py::object(copy_rows<T>(d, {c.mu}, m)) : py::none();
  py::object contacts =
      py::cast(Contacts(a, bb, copy_rows<T>(d, {c.c.x, c.c.y, c.c.z}, m), copy_rows<T>(d, {c.n.x, c.n.y, c.n.z}, m), e,
                        static_cast<double>(c.uniform_e), mu));
  return py::make_tuple(bodies, contacts);
}

template <class T>
py::tuple scene_to_python(const Scene<T>& s, Dtype d) {
  return to_python<T>(s.bodies.view(), s.contacts.view(), d);
}

py::tuple generate_py(const std::string& kind, std::size_t n, std::uint64_t seed, const std::string& model,
                      bool friction, const py::object& dtype_in) {
  const Dtype d = parse_dtype(dtype_in);
  if (kind != "pairs" && kind != "debris") {
    throw py::value_error("kind must be 'pairs' or 'debris', got '" + kind + "'");
  }
  if (n < 1 || n > 0x7FFFFFFFULL) throw py::value_error("n must be from 1 to 2^31 - 1");
  GenerateOptions o;
  o.seed = seed;
  o.friction = friction;
  const std::optional<Model> m = parse_model(model);
  if (!m) throw py::value_error("generate needs a model: 'rigid', 'sphere' or 'particle'");
  o.model = *m;
  auto run = [&](auto tag) {
    using T = decltype(tag);
    Scene<T> s;
    {
      py::gil_scoped_release release;
      s = kind == "pairs" ? generate_pairs<T>(n, o) : generate_debris<T>(n, o);
    }
    return scene_to_python<T>(s, d);
  };
  return d == Dtype::f32 ? run(float{}) : run(double{});
}

/// A scene-file error as a Python exception: an operating-system error
/// (missing file, directory, no permission) as OSError(errno, message,
/// path), which Python maps to FileNotFoundError, IsADirectoryError,
/// PermissionError...; a bad content as ValueError with the library's
/// message (file, line, row, column).
[[noreturn]] void raise_scene_error(const SceneError& e) {
  if (e.os_error() != 0) {
    PyErr_SetObject(PyExc_OSError, py::make_tuple(e.os_error(), e.reason(), e.file()).ptr());
    throw py::error_already_set();
  }
  throw py::value_error(e.what());
}

/// Runs f, translating scene-file errors (raise_scene_error).
template <class F>
auto translate_io(F&& f) {
  try {
    return f();
  } catch (const SceneError& e) {
    raise_scene_error(e);
  }
}

py::tuple read_scene_py(const std::string& bodies_csv, const std::string& contacts_csv, const py::object& dtype_in) {
  const Dtype d = parse_dtype(dtype_in);
  auto run = [&](auto tag) {
    using T = decltype(tag);
    Scene<T> s;
    translate_io([&] {
      py::gil_scoped_release release;
      const BodyTable<T> table = read_bodies<T>(bodies_csv);
      s.contacts = read_contacts<T>(contacts_csv, table.size());
      s.bodies = to_body_buffer(table);
      return 0;
    });
    return scene_to_python<T>(s, d);
  };
  return d == Dtype::f32 ? run(float{}) : run(double{});
}

// ---------------------------------------------------------------------------
// Scene files in either format, the binary one mapped (collide.load/save).
// ---------------------------------------------------------------------------

/// What keeps a loaded file's mapping alive: the base object of every array
/// that points into it. `address` and `size` say where the mapping lies, so
/// a caller (and the tests) can tell a view from a copy.
struct MappedFile {
  std::shared_ptr<const void> owner;
  std::string path;
  std::uintptr_t address = 0;
  std::size_t size = 0;
};

/// A (rows, n) array over columns `cols` where they lie, when they lie one
/// stride apart in `file`'s mapping (as collide's writer places them), read
/// only; else a copy.
template <class T>
py::array columns_array(Dtype d, const std::vector<const T*>& cols, std::size_t n, const py::object& file,
                        const MappedFile& mapped) {
  const auto inside = [&](const T* p) {
    const auto a = reinterpret_cast<std::uintptr_t>(p);
    return mapped.size != 0 && a >= mapped.address && a + n * sizeof(T) <= mapped.address + mapped.size;
  };
  bool in_place = n > 0;
  std::ptrdiff_t stride = 0;
  for (std::size_t r = 0; r < cols.size() && in_place; ++r) {
    in_place = inside(cols[r]);
    if (r == 1) stride = reinterpret_cast<const char*>(cols[1]) - reinterpret_cast<const char*>(cols[0]);
    if (r >= 1 && in_place) {
      in_place = stride >= static_cast<std::ptrdiff_t>(n * sizeof(T)) &&
                 reinterpret_cast<const char*>(cols[r]) - reinterpret_cast<const char*>(cols[r - 1]) == stride;
    }
  }
  if (!in_place) {
    py::array a = cols.size() == 1 ? new_array(d, {static_cast<py::ssize_t>(n)})
                                   : new_array(d, {static_cast<py::ssize_t>(cols.size()), static_cast<py::ssize_t>(n)});
    T* o = data<T>(a);
    for (const T* c : cols) {
      std::copy(c, c + n, o);
      o += n;
    }
    return a;
  }
  std::vector<py::ssize_t> shape, strides;
  if (cols.size() > 1) {
    shape.push_back(static_cast<py::ssize_t>(cols.size()));
    strides.push_back(stride);
  }
  shape.push_back(static_cast<py::ssize_t>(n));
  strides.push_back(sizeof(T));
  py::array a(numpy_dtype(d), shape, strides, cols[0], file);
  // The mapping is private and read-only: the array says so.
  py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return a;
}

template <class T>
py::tuple load_t(const std::string& bodies_path, const std::string& contacts_path, Dtype d) {
  std::shared_ptr<LoadedBodies<T>> lb;
  std::shared_ptr<LoadedContacts<T>> lc;
  translate_io([&] {
    py::gil_scoped_release release;
    lb = std::make_shared<LoadedBodies<T>>(load_bodies<T>(bodies_path, scene_format_of(bodies_path)));
    lc = std::make_shared<LoadedContacts<T>>(
        load_contacts<T>(contacts_path, scene_format_of(contacts_path), lb->size()));
    return 0;
  });
  const auto file_object = [](std::shared_ptr<const void> owner, const std::string& path, std::string_view bytes) {
    MappedFile f{std::move(owner), path, reinterpret_cast<std::uintptr_t>(bytes.data()), bytes.size()};
    return py::cast(std::move(f));
  };
  const py::object bfile = file_object(lb, bodies_path, lb->mapped_bytes());
  const py::object cfile = file_object(lc, contacts_path, lc->mapped_bytes());
  const MappedFile& bm = bfile.cast<const MappedFile&>();
  const MappedFile& cm = cfile.cast<const MappedFile&>();

  const BodyColumns<T>& bc = lb->columns();
  const std::size_t n = bc.count;
  // The inverses the solver takes are computed; q and p stay in the file;
  // v and w are copied, since a solve writes them.
  py::array inv_mass = new_array(d, {static_cast<py::ssize_t>(n)});
  py::array inv_inertia = new_array(d, {3, static_cast<py::ssize_t>(n)});
  {
    T* im = data<T>(inv_mass);
    const Vec3Array<T> ii = vec3<T>(inv_inertia);
    py::gil_scoped_release release;
    inverses_of(bc, im, ii);
  }
  const auto cols = [&bc](std::size_t first, std::size_t count) {
    return std::vector<const T*>(bc.column.begin() + first, bc.column.begin() + first + count);
  };
  const auto copy = [&](std::size_t first) {
    return copy_rows<T>(d, {bc.column[first], bc.column[first + 1], bc.column[first + 2]}, n);
  };
  py::object bodies = py::cast(Bodies(inv_mass, inv_inertia, columns_array<T>(d, cols(4, 4), n, bfile, bm),
                                      columns_array<T>(d, cols(8, 3), n, bfile, bm), copy(11), copy(14)));

  const ContactView<T>& v = lc->view();
  const std::size_t m = v.count;
  const auto index_array = [&](const BodyIndex* ids) -> py::array {
    const auto a = reinterpret_cast<std::uintptr_t>(ids);
    if (cm.size != 0 && m != 0 && a >= cm.address && a + m * sizeof(BodyIndex) <= cm.address + cm.size) {
      py::array r(py::dtype::of<std::uint32_t>(), {static_cast<py::ssize_t>(m)}, {}, ids, cfile);
      py::detail::array_proxy(r.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
      return r;
    }
    py::array_t<std::uint32_t> r(static_cast<py::ssize_t>(m));
    std::copy(ids, ids + m, r.mutable_data());
    return r;
  };
  py::object mu = v.mu ? py::object(columns_array<T>(d, {v.mu}, m, cfile, cm)) : py::none();
  py::object contacts = py::cast(Contacts(
      index_array(v.a), index_array(v.b), columns_array<T>(d, {v.c.x, v.c.y, v.c.z}, m, cfile, cm),
      columns_array<T>(d, {v.n.x, v.n.y, v.n.z}, m, cfile, cm), columns_array<T>(d, {v.e}, m, cfile, cm), 1.0, mu));
  return py::make_tuple(bodies, contacts);
}

py::tuple load_py(const std::string& bodies_path, const std::string& contacts_path, const py::object& dtype_in) {
  Dtype d = Dtype::f64;
  if (!dtype_in.is_none()) {
    d = parse_dtype(dtype_in);
  } else if (scene_format_of(bodies_path) == SceneFormat::npz) {
    // A binary scene in its own precision: mapped, not converted.
    try {
      d = npz_scene_precision(NpzArchive::map(bodies_path)) == NpyType::f4 ? Dtype::f32 : Dtype::f64;
    } catch (const SceneError& e) {
      raise_scene_error(e);
    }
  }
  return d == Dtype::f32 ? load_t<float>(bodies_path, contacts_path, d) : load_t<double>(bodies_path, contacts_path, d);
}

template <class T>
void write_scene_t(const std::string& bodies_csv, const std::string& contacts_csv, const Bodies& bodies,
                   const Contacts& contacts) {
  const BodyView<T> bv = bodies.view<T>();
  const ContactView<T> cv = contacts.view<T>();
  ImpulseBuffer<T> scratch(contacts.count);
  validate_or_throw<T>(bodies, contacts, scratch.view());
  translate_io([&] {
    py::gil_scoped_release release;
    // Physical units from the inverses (1/0 gives inf), written by the
    // library's writers: rows formatted in parallel blocks, a few blocks in
    // memory at a time.
    const BodyTable<T> table = to_body_table(const_view(bv));
    OutputFile ob(bodies_csv), oc(contacts_csv);
    write_body_table(ob, scene_format_of(bodies_csv), columns_of(table));
    write_contacts(oc, scene_format_of(contacts_csv), cv);
    ob.commit();
    oc.commit();
    return 0;
  });
}

void write_scene_py(const std::string& bodies_csv, const std::string& contacts_csv, const Bodies& bodies,
                    const Contacts& contacts) {
  require_same_dtype(bodies, contacts);
  if (bodies.dtype == Dtype::f32) {
    write_scene_t<float>(bodies_csv, contacts_csv, bodies, contacts);
  } else {
    write_scene_t<double>(bodies_csv, contacts_csv, bodies, contacts);
  }
}

/// Bodies from physical units: mass (inf = immovable), principal moments
/// (inf = no rotation about that axis), any non-zero quaternion (normalised),
/// as BodyBuffer::set stores them. Each body is checked with the library's
/// rules (collide/rules.hpp): ValueError("from_physical: body 3, column 'm':
/// mass must be > 0, got -1"), the reason the scene reader gives.
py::object from_physical_py(const py::object& m_in, const py::object& inertia_in, const py::object& q_in,
                            const py::object& p_in, const py::object& v_in, const py::object& w_in,
                            const py::object& dtype_in) {
  const Dtype d = parse_dtype(dtype_in);
  const py::dtype dt = numpy_dtype(d);
  const char* dn = dtype_name(d);
  const std::string owner = "from_physical";
  const py::array m = checked_array(owner, "m", m_in, dt, dn, 0, false);
  const py::array I = checked_array(owner, "inertia", inertia_in, dt, dn, 3, false);
  const py::array q = checked_array(owner, "q", q_in, dt, dn, 4, false);
  const py::array p = checked_array(owner, "p", p_in, dt, dn, 3, false);
  const py::array v = checked_array(owner, "v", v_in, dt, dn, 3, false);
  const py::array w = checked_array(owner, "w", w_in, dt, dn, 3, false);
  const std::size_t n = length(m);
  for (const auto& [name, a] :
       {std::pair<const char*, const py::array*>{"inertia", &I}, {"q", &q}, {"p", &p}, {"v", &v}, {"w", &w}}) {
    require_length(owner, name, *a, n, "m");
  }
  auto run = [&](auto tag) {
    using T = decltype(tag);
    BodyBuffer<T> buffer(n);
    const T* pm = data<T>(m);
    for (std::size_t i = 0; i < n; ++i) {
      BodyRecord<T> r;
      r.m = pm[i];
      for (int k = 0; k < 3; ++k) {
        r.I[k] = row<T>(I, k)[i];
        r.p[k] = row<T>(p, k)[i];
        r.v[k] = row<T>(v, k)[i];
        r.w[k] = row<T>(w, k)[i];
      }
      for (int k = 0; k < 4; ++k) r.q[k] = row<T>(q, k)[i];
      if (const std::optional<Defect> defect = body_defect(r)) {
        throw py::value_error(owner + ": body " + std::to_string(i) + ", column '" + std::string(defect->column) +
                              "': " + defect->reason);
      }
      buffer.set(i, r);
    }
    const BodyView<const T> b = std::as_const(buffer).view();
    return py::cast(Bodies(copy_rows<T>(d, {b.inv_mass}, n),
                           copy_rows<T>(d, {b.inv_inertia.x, b.inv_inertia.y, b.inv_inertia.z}, n),
                           copy_rows<T>(d, {b.q.w, b.q.x, b.q.y, b.q.z}, n), copy_rows<T>(d, {b.p.x, b.p.y, b.p.z}, n),
                           copy_rows<T>(d, {b.v.x, b.v.y, b.v.z}, n), copy_rows<T>(d, {b.w.x, b.w.y, b.w.z}, n)));
  };
  return d == Dtype::f32 ? run(float{}) : run(double{});
}

// ---------------------------------------------------------------------------
// The report.
// ---------------------------------------------------------------------------

/// f() (a report measurement) without the GIL; options out of range
/// (std::invalid_argument) become ValueError.
template <class F>
auto measure_without_gil(F&& f) {
  try {
    py::gil_scoped_release release;
    return f();
  } catch (const std::invalid_argument& e) {
    throw py::value_error(e.what());
  }
}

py::list report_py(std::size_t n, std::optional<std::size_t> debris_n, std::optional<std::size_t> pile_n,
                   std::vector<int> threads, std::size_t sample, int runs, std::uint64_t seed, bool quick) {
  ReportOptions o;
  o.n = n;
  o.debris_n = debris_n ? *debris_n : std::min<std::size_t>(n, o.debris_n);
  o.pile_n = pile_n ? *pile_n : std::min<std::size_t>(n, o.pile_n);
  o.threads = std::move(threads);
  o.sample = sample;
  o.runs = runs;
  o.seed = seed;
  o.quick = quick;
  const Report r = measure_without_gil([&] { return measure_report(o); });
  py::list rows;
  for (const ReportRow& x : r.rows) {
    py::dict d;
    d["scene"] = x.scene;
    d["variant"] = x.variant;
    d["model"] = x.model;
    d["precision"] = x.precision;
    d["simd"] = x.simd;
    d["friction"] = x.friction;
    d["threads"] = x.threads;
    d["n"] = x.n;
    d["lanes"] = x.lanes;
    d["isa"] = x.isa;
    d["layout"] = x.layout;
    d["runs"] = x.runs;
    d["seconds"] = x.seconds;
    d["collisions_per_second"] = x.collisions_per_second;
    d["bytes_per_collision"] = x.bytes_per_collision;
    d["bandwidth_fraction"] = x.bandwidth_fraction;
    d["error_sample"] = x.error_sample;
    d["eps"] = x.eps;
    d["max_err_eps"] = x.max_err_eps;
    d["p99_err_eps"] = x.p99_err_eps;
    d["max_rel_err"] = x.max_rel_err;
    d["momentum_drift"] = x.momentum_drift;
    d["angular_momentum_drift"] = x.angular_momentum_drift;
    d["energy_drift"] = x.energy_drift;
    d["note"] = x.note;
    rows.append(d);
  }
  return rows;
}

/// The hard section alone (measure_hard_report), one dict per HardRow.
py::list report_hard_py(std::size_t n, int runs) {
  ReportOptions o;
  o.hard = true;
  o.hard_n = n;
  o.runs = runs;
  const std::vector<HardRow> hard = measure_without_gil([&] { return measure_hard_report(o); });
  py::list rows;
  for (const HardRow& x : hard) {
    py::dict d;
    d["family"] = x.family;
    d["model"] = x.model;
    d["precision"] = x.precision;
    d["mode"] = x.mode;
    d["shared"] = x.shared;
    d["n"] = x.n;
    d["acting"] = x.acting;
    d["threads"] = x.threads;
    d["isa"] = x.isa;
    d["runs"] = x.runs;
    d["seconds"] = x.seconds;
    d["collisions_per_second"] = x.collisions_per_second;
    d["max_err_eps"] = x.max_err_eps;
    d["p99_err_eps"] = x.p99_err_eps;
    // NaN where not measured (double without a __float128 reference): None, as the JSON's null.
    d["max_err_ulps"] = std::isnan(x.max_err_ulps) ? py::object(py::none()) : py::object(py::float_(x.max_err_ulps));
    d["judge"] = x.judge;
    rows.append(d);
  }
  return rows;
}

}  // namespace
}  // namespace collide::python

PYBIND11_MODULE(_collide, m) {
  using namespace collide::python;
  namespace c = collide;
  m.doc() = "collide: batched rigid-body collision impulses (the C++ extension; use the collide package)";

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
      .def("__len__", [](const Bodies& b) { return b.count; });

  py::class_<PackedBodies>(m, "PackedBodies")
      .def(py::init<const py::object&, const std::string&, const py::object&>(), py::arg("records"), py::kw_only(),
           py::arg("model") = "auto", py::arg("inv_mass") = py::none())
      .def_readonly("records", &PackedBodies::records)
      // The rigid records' side array, or None; collide.PackedBodies.inv_mass
      // (__init__.py) gives every model's inverse masses.
      .def_property_readonly("_inv_mass", &PackedBodies::inv_mass_object)
      .def_property_readonly("model", [](const PackedBodies& b) { return std::string(c::to_string(b.model)); })
      .def_property_readonly("dtype", [](const PackedBodies& b) { return numpy_dtype(b.dtype); })
      .def_property_readonly("record_dtype", [](const PackedBodies& b) { return record_dtype(b.model, b.dtype); })
      .def("__len__", [](const PackedBodies& b) { return b.count; });
  m.def(
      "packed_dtype",
      [](const std::string& model, const py::object& dtype) {
        const std::optional<c::Model> mm = parse_model(model);
        if (!mm) throw py::value_error("packed_dtype needs a model: 'rigid', 'sphere' or 'particle'");
        return record_dtype(*mm, parse_dtype(dtype));
      },
      py::arg("model"), py::arg("dtype"));
  m.def(
      "packed_alignment",
      [](const std::string& model, const py::object& dtype) {
        const std::optional<c::Model> mm = parse_model(model);
        if (!mm) throw py::value_error("packed_alignment needs a model: 'rigid', 'sphere' or 'particle'");
        return record_align(*mm, parse_dtype(dtype));
      },
      py::arg("model"), py::arg("dtype"));
  m.def("pack_into", &pack_into, py::arg("bodies"), py::arg("packed"));
  m.def(
      "unpack_into", [](const PackedBodies& packed, const Bodies& bodies) { unpack_into(packed, bodies, false); },
      py::arg("packed"), py::arg("bodies"));
  m.def(
      "unpack_velocities_into",
      [](const PackedBodies& packed, const Bodies& bodies) { unpack_into(packed, bodies, true); }, py::arg("packed"),
      py::arg("bodies"));
  m.def(
      "choose_model",
      [](const Bodies& bodies, const Contacts& contacts) {
        require_same_dtype(bodies, contacts);
        const auto run = [&](auto tag) {
          using T = decltype(tag);
          c::ImpulseBuffer<T> scratch(contacts.count);
          validate_or_throw<T>(bodies, contacts, scratch.view());
          return std::string(c::to_string(c::choose_model(bodies.view<T>(), contacts.view<T>())));
        };
        return bodies.dtype == Dtype::f32 ? run(float{}) : run(double{});
      },
      py::arg("bodies"), py::arg("contacts"));
  m.def(
      "model_misfit",
      [](const Bodies& bodies, const Contacts& contacts, const std::string& model) {
        require_same_dtype(bodies, contacts);
        const std::optional<c::Model> mm = parse_model(model);
        if (!mm) throw py::value_error("model_misfit needs a model: 'rigid', 'sphere' or 'particle'");
        const auto run = [&](auto tag) {
          using T = decltype(tag);
          return c::model_misfit(*mm, bodies.view<T>(), contacts.view<T>());
        };
        return bodies.dtype == Dtype::f32 ? run(float{}) : run(double{});
      },
      py::arg("bodies"), py::arg("contacts"), py::arg("model"));

  py::class_<Contacts>(m, "Contacts")
      .def(py::init<const py::object&, const py::object&, const py::object&, const py::object&, const py::object&,
                    double, const py::object&>(),
           py::arg("a"), py::arg("b"), py::arg("c"), py::arg("n"), py::arg("e") = py::none(),
           py::arg("uniform_e") = 1.0, py::arg("mu") = py::none())
      .def_readonly("a", &Contacts::a)
      .def_readonly("b", &Contacts::b)
      .def_readonly("c", &Contacts::c)
      .def_readonly("n", &Contacts::n)
      .def_property_readonly("e", &Contacts::e_object)
      .def_property_readonly("mu", &Contacts::mu_object)
      .def_readonly("uniform_e", &Contacts::uniform_e)
      .def_property_readonly("dtype", [](const Contacts& c) { return numpy_dtype(c.dtype); })
      .def("__len__", [](const Contacts& c) { return c.count; });

  py::class_<PySchedule>(m, "Schedule")
      .def(py::init(&PySchedule::make<Bodies>), py::arg("bodies"), py::arg("contacts"))
      .def(py::init(&PySchedule::make<PackedBodies>), py::arg("bodies"), py::arg("contacts"))
      .def_property_readonly("batches", [](const PySchedule& s) { return s.schedule.batch_count(); })
      .def_property_readonly("largest_batch", [](const PySchedule& s) { return s.schedule.largest_batch(); })
      .def_readonly("build_seconds", &PySchedule::build_seconds);

  py::class_<PySolver>(m, "Solver")
      .def(py::init<const std::string&, int, const py::object&, const std::string&>(), py::kw_only(),
           py::arg("path") = "simd", py::arg("threads") = 0, py::arg("isa") = py::none(), py::arg("accuracy") = "fast")
      .def_property_readonly("path", [](const PySolver& s) { return c::to_string(s.solver->options().path); })
      .def_property_readonly("threads", [](const PySolver& s) { return s.solver->options().threads; })
      .def_property_readonly("isa", [](const PySolver& s) { return c::to_string(s.solver->isa()); })
      .def_property_readonly("accuracy", [](const PySolver& s) { return c::to_string(s.solver->options().accuracy); })
      .def("solve", &PySolver::solve<Bodies>, py::arg("bodies"), py::arg("contacts"), py::kw_only(),
           py::arg("model") = "auto", py::arg("schedule") = nullptr, py::arg("out") = py::none(),
           py::arg("check") = true, py::arg("impacts") = true)
      .def("solve", &PySolver::solve<PackedBodies>, py::arg("bodies"), py::arg("contacts"), py::kw_only(),
           py::arg("model") = "auto", py::arg("schedule") = nullptr, py::arg("out") = py::none(),
           py::arg("check") = true, py::arg("impacts") = true);

  py::class_<Reference, std::shared_ptr<Reference>>(m, "Reference")
      .def_property_readonly("J", &Reference::j_array)
      .def_property_readonly("v", [](const Reference& r) { return r.vec_array(false); })
      .def_property_readonly("w", [](const Reference& r) { return r.vec_array(true); })
      .def_property_readonly(
          "impulse_scale",
          [](const Reference& r) { return r.diag_array(&c::ReferenceContact<long double>::impulse_scale); })
      .def_property_readonly("dtype", [](const Reference& r) { return numpy_dtype(r.dtype); })
      .def("__len__", [](const Reference& r) { return r.impulses.size(); });

  m.def("reference_solve", &reference_solve_py, py::arg("bodies"), py::arg("contacts"));
  m.def("impulse_error", &impulse_error_py, py::arg("J"), py::arg("reference"));
  m.def("generate", &generate_py, py::arg("kind"), py::arg("n"), py::kw_only(), py::arg("seed") = 1,
        py::arg("model") = "rigid", py::arg("friction") = false, py::arg("dtype") = py::none());
  py::class_<MappedFile>(m, "MappedFile",
                         "A scene file mapped into memory: the base of the arrays collide.load() leaves in it.")
      .def_readonly("path", &MappedFile::path)
      .def_readonly("address", &MappedFile::address)
      .def_readonly("size", &MappedFile::size);
  m.def("load", &load_py, py::arg("bodies"), py::arg("contacts"), py::kw_only(), py::arg("dtype") = py::none());
  m.def("read_scene", &read_scene_py, py::arg("bodies_csv"), py::arg("contacts_csv"), py::kw_only(), py::arg("dtype"));
  m.def("write_scene", &write_scene_py, py::arg("bodies_csv"), py::arg("contacts_csv"), py::arg("bodies"),
        py::arg("contacts"));
  m.def("from_physical", &from_physical_py, py::arg("m"), py::arg("inertia"), py::arg("q"), py::arg("p"), py::arg("v"),
        py::arg("w"), py::arg("dtype"));
  m.def("report", &report_py, py::kw_only(), py::arg("n") = 4000000, py::arg("debris_n") = py::none(),
        py::arg("pile_n") = py::none(), py::arg("threads") = std::vector<int>{1, 2}, py::arg("sample") = 100000,
        py::arg("runs") = 5, py::arg("seed") = 1, py::arg("quick") = false);
  m.def("report_hard", &report_hard_py, py::kw_only(), py::arg("n") = 1000, py::arg("runs") = 5);
  m.attr("accurate_error_ulps") = c::kAccurateErrorUlps;
  m.attr("error_target_eps") = c::kImpulseErrorTargetEps;
  m.attr("error_bound_eps") = c::kImpulseErrorBoundEps;
  m.def(
      "simd_width",
      [](const std::string& isa, const py::object& dtype) {
        const Dtype d = parse_dtype(dtype);
        c::Isa i;
        try {
          i = c::resolve_isa(c::parse_isa(isa));
        } catch (const std::invalid_argument& e) {
          throw py::value_error(e.what());
        }
        return d == Dtype::f32 ? c::simd_width<float>(i) : c::simd_width<double>(i);
      },
      py::arg("isa") = "auto", py::arg("dtype"));
  m.def(
      "isa_supported",
      [](const std::string& isa) {
        try {
          return c::isa_supported(c::parse_isa(isa));
        } catch (const std::invalid_argument& e) {
          throw py::value_error(e.what());
        }
      },
      py::arg("isa"));
  m.def("best_isa", [] { return std::string(c::to_string(c::best_isa())); });

  // By value: pybind11's translator is a void (*)(std::exception_ptr).
  py::register_exception_translator([](std::exception_ptr p) {  // NOLINT(performance-unnecessary-value-param)
    try {
      if (p) std::rethrow_exception(p);
    } catch (const c::SceneError& e) {
      try {
        raise_scene_error(e);
      } catch (py::error_already_set& set) {
        set.restore();
      } catch (const py::value_error& v) {
        PyErr_SetString(PyExc_ValueError, v.what());
      }
    }
  });
}
