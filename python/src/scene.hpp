// python/src/scene.hpp - collide.Bodies and collide.Contacts: a scene over
// the caller's arrays, and what the other topics ask of it.
//
// Design notes
// ------------
// * Bodies and Contacts keep the very arrays given (no copy, ever) and hand
//   the library SoA views of them (view<T>()). Their constructors check the
//   layouts (arrays.hpp); the values are checked where they are used, by the
//   library's validate() (validate_or_throw), so that a frame loop can skip
//   that pass (Solver.solve(check=False)).
// * Bodies and PackedBodies (packed_bodies.hpp) are the two kinds of bodies
//   a solve takes. Each kind gives the same overloads, found by argument-
//   dependent lookup from the generic code of bind_solve.cpp:
//   validate_values, build_schedule, solve_model, run_solve.
// * New scenes (generated, read, from physical units) are Python objects
//   over new arrays: bodies_object() and contacts_object() copy a library
//   view into them.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstddef>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "arrays.hpp"
#include "collide/bodies.hpp"
#include "collide/contacts.hpp"
#include "collide/io/scene_io.hpp"
#include "collide/model.hpp"
#include "collide/schedule.hpp"
#include "collide/solve.hpp"
#include "collide/validate.hpp"

namespace collide::python {

/// N bodies over the caller's arrays: inv_mass (N,), inv_inertia, p, v, w
/// (3, N), q (4, N); one dtype; v and w writeable.
struct Bodies {
  py::array inv_mass, inv_inertia, q, p, v, w;
  Dtype dtype = Dtype::f64;
  std::size_t count = 0;

  Bodies(const py::object& inv_mass_in, const py::object& inv_inertia_in, const py::object& q_in,
         const py::object& p_in, const py::object& v_in, const py::object& w_in);

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

/// M contacts over the caller's arrays: a, b uint32 (M,), c, n (3, M), e and
/// mu (M,) or None (uniform_e for every contact; frictionless).
struct Contacts {
  py::array a, b, c, n;
  std::optional<py::array> e, mu;
  double uniform_e = 1;
  Dtype dtype = Dtype::f64;
  std::size_t count = 0;

  Contacts(const py::object& a_in, const py::object& b_in, const py::object& c_in, const py::object& n_in,
           const py::object& e_in, double uniform_e_in, const py::object& mu_in);

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
};

/// The arrays of a scene as the bytes a solve touches (add_bytes of
/// arrays.hpp, for require_disjoint): the bodies' v and w written, every
/// other array read.
void add_bytes(std::vector<ArrayBytes>& out, const Bodies& b);
void add_bytes(std::vector<ArrayBytes>& out, const Contacts& c);

/// A new collide.Bodies over copies of `b`.
/// 1/m and 1/I of `columns` as new (N,) and (3, N) arrays of dtype `d`: the
/// readers' inverses_of (collide/io/scene_io.hpp), without the GIL. Only m
/// and the moments are read.
template <class T>
std::pair<py::array, py::array> inverse_arrays(const BodyColumns<T>& columns, Dtype d) {
  const auto n = static_cast<py::ssize_t>(columns.count);
  py::array inv_mass = new_array(d, {n});
  py::array inv_inertia = new_array(d, {3, n});
  T* const im = data<T>(inv_mass);
  const Vec3Array<T> ii = vec3<T>(inv_inertia);
  {
    py::gil_scoped_release release;
    inverses_of(columns, im, ii);
  }
  return {std::move(inv_mass), std::move(inv_inertia)};
}

template <class T>
py::object bodies_object(const BodyView<const T>& b, Dtype d) {
  const std::size_t n = b.count;
  return py::cast(Bodies(copy_rows<T>(d, {b.inv_mass}, n),
                         copy_rows<T>(d, {b.inv_inertia.x, b.inv_inertia.y, b.inv_inertia.z}, n),
                         copy_rows<T>(d, {b.q.w, b.q.x, b.q.y, b.q.z}, n), copy_rows<T>(d, {b.p.x, b.p.y, b.p.z}, n),
                         copy_rows<T>(d, {b.v.x, b.v.y, b.v.z}, n), copy_rows<T>(d, {b.w.x, b.w.y, b.w.z}, n)));
}

/// A new collide.Contacts over copies of `c`.
template <class T>
py::object contacts_object(const ContactView<T>& c, Dtype d) {
  const std::size_t m = c.count;
  py::array_t<std::uint32_t> a(static_cast<py::ssize_t>(m)), b(static_cast<py::ssize_t>(m));
  std::copy(c.a, c.a + m, a.mutable_data());
  std::copy(c.b, c.b + m, b.mutable_data());
  const py::object e = c.e ? py::object(copy_rows<T>(d, {c.e}, m)) : py::none();
  const py::object mu = c.mu ? py::object(copy_rows<T>(d, {c.mu}, m)) : py::none();
  return py::cast(Contacts(a, b, copy_rows<T>(d, {c.c.x, c.c.y, c.c.z}, m), copy_rows<T>(d, {c.n.x, c.n.y, c.n.z}, m),
                           e, static_cast<double>(c.uniform_e), mu));
}

/// (Bodies, Contacts) over copies of a scene's views.
template <class T>
py::tuple scene_objects(const BodyView<const T>& b, const ContactView<T>& c, Dtype d) {
  return py::make_tuple(bodies_object<T>(b, d), contacts_object<T>(c, d));
}

/// TypeError unless bodies (Bodies or PackedBodies) and contacts share a dtype.
template <class B>
void require_same_dtype(const B& bodies, const Contacts& contacts) {
  if (bodies.dtype != contacts.dtype) {
    throw py::type_error(std::string("bodies are ") + dtype_name(bodies.dtype) + " but contacts are " +
                         dtype_name(contacts.dtype) + ": one precision per solve");
  }
}

/// A model= argument: "auto" gives nothing; ValueError for an unknown name.
std::optional<Model> parse_model(const std::string& s);
/// A model= argument that must name a model (not "auto"): ValueError("<who>
/// needs a model: 'rigid', 'sphere' or 'particle'") otherwise.
Model parse_named_model(const std::string& s, const char* who);

// The steps of a solve on SoA bodies (the overloads for records are in
// packed_bodies.hpp).

template <class T>
Validation validate_values(const Bodies& b, const ContactView<T>& cv, const ImpulseView<T>& jv) {
  return validate(b.view<T>(), cv, jv);
}

/// The schedule reads only the inverse masses (immovable bodies do not
/// conflict).
template <class T>
void build_schedule(Schedule& schedule, const ContactView<T>& cv, const Bodies& b) {
  schedule.build(cv, b.view<T>());
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

template <class T>
SolveStats run_solve(const Solver& solver, Model model, const Bodies& b, const ContactView<T>& cv,
                     const ImpulseView<T>& jv, const Schedule& schedule) {
  return solver.solve(model, b.view<T>(), cv, jv, schedule);
}

/// The library's validate() on every value of the scene (in T), against
/// impulse storage of the right size; ValueError naming the array and the
/// first bad element ("bodies.v.y[9] = nan: must be finite").
template <class T, class B>
void validate_or_throw(const B& bodies, const Contacts& contacts) {
  ImpulseBuffer<T> scratch(contacts.count);
  if (const Validation v = validate_values(bodies, contacts.view<T>(), scratch.view()); !v) {
    throw py::value_error(v.message);
  }
}

}  // namespace collide::python
