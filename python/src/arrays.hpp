// python/src/arrays.hpp - NumPy arrays at the module's boundary: the checks
// of one array argument and the views of its buffer.
//
// Design notes
// ------------
// * Zero copy: the library runs on SoA views of the caller's buffers (row k
//   of a (3, N) array is component k). Only arrays that already have the
//   right dtype, shape and layout are accepted (TypeError naming the array):
//   a silent conversion would copy, and v and w could then not be updated
//   in place. Lengths that disagree are a ValueError naming both arrays.
// * Every message names where the array came from: "<owner>.<name>", e.g.
//   "bodies.v", "packed.inv_mass", "solve.out".
// * One scene, one precision: Dtype is float32 or float64, and with_dtype()
//   runs a generic lambda on float or double values accordingly.
// * No value is checked here: values are the library's (validate() for
//   arrays in kernel units, collide/rules.hpp for physical units).
#pragma once

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <algorithm>
#include <cstddef>
#include <initializer_list>
#include <string>
#include <utility>
#include <vector>

#include "collide/bodies.hpp"
#include "collide/validate.hpp"

namespace collide::python {

namespace py = pybind11;

/// str(h).
std::string text(const py::handle& h);

/// "1 contact", "2 contacts": a count and its noun, for reprs.
inline std::string counted(std::size_t n, const char* one, const char* many) {
  return std::to_string(n) + " " + (n == 1 ? one : many);
}

/// The precision of a scene.
enum class Dtype { f32, f64 };
/// "float32" or "float64".
const char* dtype_name(Dtype d);
/// numpy.float32 or numpy.float64.
py::dtype numpy_dtype(Dtype d);
/// A dtype argument (numpy.float32, "float64", ...); TypeError for another.
Dtype parse_dtype(const py::object& dtype);
/// An integer argument from `least` to `most`: a Python int (or anything
/// with __index__, such as numpy.int64), else TypeError, and in the range,
/// else ValueError, both saying "<name> must be an integer from 1 to
/// 1000000, got 2.5", in the caller's terms rather than pybind11's.
long long integer_argument(const py::handle& obj, const std::string& name, long long least, long long most);

/// The dtype of a scene, from its first floating-point array `what`
/// (TypeError when it is not an ndarray of float32 or float64).
Dtype scene_dtype(const std::string& what, const py::handle& obj);
/// The dtype of a scene whose floating-point arrays are `arrays` (name,
/// object; None for an optional array not given): the one they share. When
/// they differ, a TypeError naming the array that differs from the others
/// and what the others are ("bodies.inv_mass has dtype float32, expected
/// float64 like every other array of bodies"); with as many of each, the
/// first array's dtype is the scene's. An array that is not an ndarray of
/// float32 or float64 is left to checked_array's message.
Dtype scene_dtype(const std::string& owner, std::initializer_list<std::pair<const char*, py::handle>> arrays);

/// f(float{}) or f(double{}): a generic lambda instantiated for the values
/// of the precision `d`.
template <class F>
decltype(auto) with_dtype(Dtype d, F&& f) {
  return d == Dtype::f32 ? f(float{}) : f(double{});
}

/// "(2, 80)", "(10,)".
std::string shape_text(const py::array& a);

/// The checks of one array argument: an ndarray, of `dtype`, C-contiguous
/// (or, for a (rows, N) array, each row contiguous with the rows one stride
/// apart: what collide.load leaves in a mapped file), aligned, writeable
/// when the solve writes it, of `rows` rows (0: 1-D). Throws TypeError
/// naming it ("<owner>.<name>"); for an array the solve writes, the
/// message says that a converted or contiguous copy would receive the
/// results instead.
py::array checked_array(const std::string& owner, const char* name, const py::handle& obj, const py::dtype& dtype,
                        const char* dtype_text, int rows, bool writeable);

/// The length of an array (its last dimension).
inline std::size_t length(const py::array& a) { return static_cast<std::size_t>(a.shape(a.ndim() - 1)); }

/// ValueError("<owner>.<name> has 79 elements, <first> has 80") unless `a`
/// has n elements.
void require_length(const std::string& owner, const char* name, const py::array& a, std::size_t n, const char* first);

/// Appends the bytes a solve touches in `a`, an array of scene values
/// checked by checked_array, "<owner>.<name>", to `out`
/// (collide::validate_disjoint's list): each row of a (rows, N) array apart,
/// since the rows of one array may lie apart in a larger one (a (6, N)
/// array's even rows as v, its odd rows as w), else the whole array. `owner`
/// and `name` must outlive `out` (string literals).
void add_bytes(std::vector<ArrayBytes>& out, const char* owner, const char* name, const py::array& a, bool written);
/// ValueError("bodies.v and bodies.w share memory: the solve writes both")
/// when an array of `arrays` the solve writes shares memory with another.
void require_disjoint(const std::vector<ArrayBytes>& arrays);

/// Whether NumPy lets the array be written.
bool writeable(const py::array& a);
/// Marks an array read-only (a view of a read-only mapping).
void set_read_only(py::array& a);

/// A new C-contiguous array of the scene's dtype (uninitialised).
inline py::array new_array(Dtype d, std::vector<py::ssize_t> shape) {
  return py::array(numpy_dtype(d), std::move(shape));
}

/// The buffer of an array (checked_array vouches for its dtype).
template <class T>
T* data(const py::array& a) {
  return static_cast<T*>(const_cast<void*>(a.data()));
}
/// Row r of a (rows, N) array (rows contiguous, checked_array).
template <class T>
T* row(const py::array& a, py::ssize_t r) {
  return reinterpret_cast<T*>(static_cast<char*>(const_cast<void*>(a.data())) + r * a.strides(0));
}
/// The three rows of a (3, N) array.
template <class T>
Vec3Array<T> vec3(const py::array& a) {
  return {row<T>(a, 0), row<T>(a, 1), row<T>(a, 2)};
}

/// A new array of `dtype` holding `row_count` rows of n values: (n,) for one
/// row, else (row_count, n).
template <class T>
py::array copy_rows(const py::dtype& dtype, const T* const* rows, std::size_t row_count, std::size_t n) {
  std::vector<py::ssize_t> shape{static_cast<py::ssize_t>(n)};
  if (row_count != 1) shape.insert(shape.begin(), static_cast<py::ssize_t>(row_count));
  py::array a(dtype, shape);
  T* const o = data<T>(a);
  // On TBB's threads without the GIL: a new array's first touch (the kernel
  // zeroing its pages) costs as much as the copy, and both spread over cores.
  constexpr std::size_t kGrain = std::size_t{1} << 16;
  const auto copy = [&](std::size_t begin, std::size_t end) {
    for (std::size_t r = 0; r < row_count; ++r) std::copy(rows[r] + begin, rows[r] + end, o + r * n + begin);
  };
  if (n < 2 * kGrain) {
    copy(0, n);
  } else {
    py::gil_scoped_release release;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, kGrain),
                      [&](const tbb::blocked_range<std::size_t>& r) { copy(r.begin(), r.end()); });
  }
  return a;
}
template <class T>
py::array copy_rows(Dtype d, std::initializer_list<const T*> rows, std::size_t n) {
  return copy_rows<T>(numpy_dtype(d), rows.begin(), rows.size(), n);
}

}  // namespace collide::python
