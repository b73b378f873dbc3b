// python/src/arrays.cpp - the checks of one NumPy array argument (arrays.hpp):
// type, dtype, shape, layout, alignment and write access, each refused with
// a TypeError that names the array; lengths with a ValueError.
#include "arrays.hpp"

#include <algorithm>

namespace collide::python {

std::string text(const py::handle& h) { return py::str(h).cast<std::string>(); }

const char* dtype_name(Dtype d) { return d == Dtype::f32 ? "float32" : "float64"; }

py::dtype numpy_dtype(Dtype d) { return d == Dtype::f32 ? py::dtype::of<float>() : py::dtype::of<double>(); }

Dtype parse_dtype(const py::object& dtype) {
  const py::dtype d = py::dtype::from_args(dtype);
  if (d.equal(py::dtype::of<float>())) return Dtype::f32;
  if (d.equal(py::dtype::of<double>())) return Dtype::f64;
  throw py::type_error("dtype must be numpy.float32 or numpy.float64, got " + text(dtype));
}

long long integer_argument(const py::handle& obj, const std::string& name, long long least, long long most) {
  const auto message = [&] {
    return name + " must be an integer from " + std::to_string(least) + " to " + std::to_string(most) + ", got " +
           py::repr(obj).cast<std::string>();
  };
  if (PyIndex_Check(obj.ptr()) == 0) throw py::type_error(message());
  const py::object index = py::reinterpret_steal<py::object>(PyNumber_Index(obj.ptr()));
  if (!index) throw py::error_already_set();
  int overflow = 0;
  const long long n = PyLong_AsLongLongAndOverflow(index.ptr(), &overflow);
  if (n == -1 && PyErr_Occurred() != nullptr) throw py::error_already_set();
  if (overflow != 0 || n < least || n > most) throw py::value_error(message());
  return n;
}

Dtype scene_dtype(const std::string& what, const py::handle& obj) {
  if (!py::isinstance<py::array>(obj)) {
    throw py::type_error(what + " must be a numpy.ndarray, got " + text(py::type::of(obj)));
  }
  const py::dtype d = py::reinterpret_borrow<py::array>(obj).dtype();
  if (d.equal(py::dtype::of<float>())) return Dtype::f32;
  if (d.equal(py::dtype::of<double>())) return Dtype::f64;
  throw py::type_error(what + " has dtype " + text(d) + ", expected float32 or float64");
}

Dtype scene_dtype(const std::string& owner, std::initializer_list<std::pair<const char*, py::handle>> arrays) {
  // The float32 and float64 arrays, in order; anything else is checked_array's to refuse.
  std::vector<std::pair<const char*, Dtype>> floats;
  for (const auto& [name, obj] : arrays) {
    if (!py::isinstance<py::array>(obj)) continue;
    const py::dtype d = py::reinterpret_borrow<py::array>(obj).dtype();
    if (d.equal(py::dtype::of<float>())) floats.emplace_back(name, Dtype::f32);
    if (d.equal(py::dtype::of<double>())) floats.emplace_back(name, Dtype::f64);
  }
  if (floats.empty()) return scene_dtype(owner + "." + arrays.begin()->first, arrays.begin()->second);
  const auto f32 = static_cast<std::size_t>(
      std::count_if(floats.begin(), floats.end(), [](const auto& f) { return f.second == Dtype::f32; }));
  const std::size_t f64 = floats.size() - f32;
  if (f32 == 0 || f64 == 0) return floats.front().second;
  const Dtype scene = f32 > f64 ? Dtype::f32 : f64 > f32 ? Dtype::f64 : floats.front().second;
  const auto odd = std::find_if(floats.begin(), floats.end(), [&](const auto& f) { return f.second != scene; });
  const auto like = std::find_if(floats.begin(), floats.end(), [&](const auto& f) { return f.second == scene; });
  const bool one_odd = std::min(f32, f64) == 1 && f32 != f64;
  const std::string others = one_odd ? "every other array of " + owner : owner + "." + like->first;
  throw py::type_error(owner + "." + odd->first + " has dtype " + dtype_name(odd->second) + ", expected " +
                       dtype_name(scene) + " like " + others + ": one dtype per scene (" + owner + "." + odd->first +
                       ".astype(numpy." + dtype_name(scene) + ") converts a copy)");
}

std::string shape_text(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t k = 0; k < a.ndim(); ++k) {
    if (k > 0) s += ", ";
    s += std::to_string(a.shape(k));
  }
  return s + (a.ndim() == 1 ? ",)" : ")");
}

bool writeable(const py::array& a) { return (a.flags() & py::detail::npy_api::NPY_ARRAY_WRITEABLE_) != 0; }

void set_read_only(py::array& a) {
  py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
}

py::array checked_array(const std::string& owner, const char* name, const py::handle& obj, const py::dtype& dtype,
                        const char* dtype_text, int rows, bool must_write) {
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
  // C-contiguous, or (for a (rows, N) array) each row contiguous with the
  // rows apart: what a scene file loaded in place gives (collide.load), its
  // columns at one stride in the mapping.
  const auto item = static_cast<py::ssize_t>(a.itemsize());
  const bool rows_contiguous = rows != 0 && a.shape(1) > 0 && a.strides(1) == item && a.strides(0) % item == 0 &&
                               a.strides(0) >= a.shape(1) * item;
  if ((a.flags() & py::array::c_style) == 0 && !rows_contiguous) {
    throw py::type_error(what + " must be C-contiguous " +
                         (must_write ? "(the solve writes into it in place: a contiguous copy, "
                                       "numpy.ascontiguousarray, would receive the results instead, so pass that "
                                       "copy and read the results from it)"
                                     : "(numpy.ascontiguousarray makes a contiguous copy)"));
  }
  if ((a.flags() & py::detail::npy_api::NPY_ARRAY_ALIGNED_) == 0) throw py::type_error(what + " must be aligned");
  if (must_write && !writeable(a)) throw py::type_error(what + " must be writeable: the solve updates it in place");
  return a;
}

void require_length(const std::string& owner, const char* name, const py::array& a, std::size_t n, const char* first) {
  if (length(a) != n) {
    throw py::value_error(owner + "." + name + " has " + std::to_string(length(a)) + " elements, " + first + " has " +
                          std::to_string(n));
  }
}

void add_bytes(std::vector<ArrayBytes>& out, const char* owner, const char* name, const py::array& a, bool written) {
  if (a.ndim() != 2) {
    out.push_back({owner, name, a.data(), static_cast<std::size_t>(a.nbytes()), written});
    return;
  }
  const auto row_bytes = static_cast<std::size_t>(a.shape(1)) * static_cast<std::size_t>(a.itemsize());
  for (py::ssize_t r = 0; r < a.shape(0); ++r) {
    out.push_back({owner, name, static_cast<const char*>(a.data()) + r * a.strides(0), row_bytes, written});
  }
}

void require_disjoint(const std::vector<ArrayBytes>& arrays) {
  if (const Validation v = validate_disjoint(arrays.data(), arrays.size()); !v) throw py::value_error(v.message);
}

}  // namespace collide::python
