// fuzz_entry.cpp - libFuzzer target: the public entry points of a solve on
// views of any shape: validate(), Schedule::build, every Solver::solve
// overload and the one-shot collide::solve(), in float and double, on both
// paths and in both accuracy modes.
//
// The bytes become views with 0 to 64 bodies and 0 to 128 contacts whose
// indices are mostly in range, sometimes just past the last body or near
// 2^32, sometimes a == b; values come from fuzz_scene.hpp's palette (NaN,
// +-inf, subnormals, +-0, 1e-30, 1e30, FLT_MAX, ...); e and mu may be null
// (uniform e, frictionless), and one array the views must have may be null
// with a count > 0, impulses may have a count other than the contacts'.
// Every call must either throw std::invalid_argument or std::length_error
// (with a message), or return; which one is decided here from the input:
// * validate() never throws; a rejection says why, and it never accepts
//   indices out of range, a == b, null arrays or a wrong impulse count;
// * Schedule::build throws exactly when an index is out of range, a == b, or
//   an array it reads is null, and is empty afterwards;
// * Solver::solve (SoA rigid, sphere and particle views, solved in place or
//   packed by the solver; the caller's packed records made with pack(); the
//   model overload) throws exactly when the impulse count differs, an array
//   its model reads is null, or the schedule was built for other counts, and
//   then writes nothing. When validate() accepted the view it returns, writes
//   every J, changes nothing but v and w (and those of no immovable body),
//   gives the same bytes on every path and layout, and its results still pass
//   validate() - always for moderate values (fuzz_scene.hpp's moderate()),
//   and up to non-finite velocities for huge ones, which the law may
//   legitimately overflow. On values validate() rejects it only has to stay
//   inside the arrays;
// * collide::solve() throws validate()'s message exactly when validate()
//   rejects, writes nothing then, and otherwise gives the bytes of
//   Solver::solve with choose_model()'s model.
// ASan and UBSan (this build) report any read or write out of bounds and
// any UB, in the library and here; the kernels' debug asserts are on.
//
// Layout: byte 0 flags (bit 0: tidy - inverse masses and moments made >= 0,
// q and n normalised, e folded into [0, 1], mu >= 0, a == b only where an
// index byte asks for it; bit 1: uniform e; bit 2: frictionless; bit 3: one
// array null, byte 3 says which; bit 4: impulses.count one more or less than
// contacts.count), byte 1 body count, byte 2 contact count, byte 3 the null
// array, byte 4 uniform e, then per body 17 values (inverse mass, 3 inverse
// moments, q, p, v, w) and per contact two index bytes and 8 values (c, n, e,
// mu). An index byte below 224 is a body (x mod the body count), 224-239 one
// of the 16 indices past the last body, 240-247 one of the 8 largest, and
// 248-255 asks for a == b (on the second index; on the first, an index near
// 2^31).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <exception>
#include <limits>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "collide/model.hpp"
#include "collide/packed.hpp"
#include "collide/schedule.hpp"
#include "collide/solve.hpp"
#include "collide/validate.hpp"
#include "fuzz_scene.hpp"

namespace {

using namespace collide;
using fuzz::Arrays;
using fuzz::fail;
using fuzz::RawScene;

/// The array an input nulls: body field 0..16 (Arrays' order), then these.
enum NullArray : int {
  kNullNone = -1,
  kNullA = 17,
  kNullB,
  kNullCx,
  kNullCy,
  kNullCz,
  kNullNx,
  kNullNy,
  kNullNz,
  kNullJx,
  kNullJy,
  kNullJz,
  kNullRecords,      // the caller's packed records
  kNullRigidInvMass  // the inverse masses beside packed rigid records
};
constexpr int kNullChoices = kNullRigidInvMass + 1;

struct Input {
  RawScene raw;
  int null = kNullNone;
  int impulse_delta = 0;  // impulses.count - contacts.count
};

std::uint32_t decode_index(std::uint8_t x, std::size_t bodies, std::uint32_t other, bool second) {
  const auto n = static_cast<std::uint32_t>(bodies);
  if (x < 224) return n > 0 ? x % n : x;
  if (x < 240) return n + (x - 224u);
  if (x < 248) return std::numeric_limits<std::uint32_t>::max() - (x - 240u);
  return second ? other : 0x80000000u + x;
}

Input decode(const std::uint8_t* data, std::size_t size) {
  fuzz::Reader in(data, size);
  Input input;
  RawScene& s = input.raw;
  const std::uint8_t flags = in.byte();
  const bool tidy = flags & 1;
  s.uniform_e = flags & 2;
  s.frictionless = flags & 4;
  s.bodies = in.byte() % 65;
  s.contacts = in.byte() % 129;
  const std::uint8_t null = in.byte();
  if (flags & 8) input.null = null % kNullChoices;
  if (flags & 16) input.impulse_delta = (s.contacts == 0 || (null & 128)) ? 1 : -1;
  s.e = in.value();
  if (tidy) s.e = std::isfinite(s.e) ? std::fmod(std::abs(s.e), 1.0) : 0.5;
  s.body.resize(s.bodies);
  for (auto& b : s.body) {
    for (double& x : b) x = in.value();
    if (tidy) {
      for (int i = 0; i < 4; ++i) b[i] = std::abs(b[i]);
      fuzz::normalise(&b[4], 4);
    }
  }
  for (std::size_t k = 0; k < s.contacts; ++k) {
    const std::uint8_t xa = in.byte(), xb = in.byte();
    const std::uint32_t a = decode_index(xa, s.bodies, 0, false);
    std::uint32_t b = decode_index(xb, s.bodies, a, true);
    // Tidy: a == b only where the byte asks for it.
    if (tidy && xa < 224 && xb < 224 && a == b && s.bodies > 1) b = static_cast<std::uint32_t>((a + 1) % s.bodies);
    s.index.push_back({a, b});
    std::array<double, 8> c{};
    for (double& x : c) x = in.value();
    if (tidy) {
      fuzz::normalise(&c[3], 3);
      c[6] = std::isfinite(c[6]) ? std::fmod(std::abs(c[6]), 1.0) : 0.5;
      c[7] = std::isfinite(c[7]) ? std::abs(c[7]) : 0.5;
    }
    s.contact.push_back(c);
  }
  return input;
}

/// Every index < the body count and a != b.
bool indices_in_range(const RawScene& s) {
  for (const auto& [a, b] : s.index) {
    if (a >= s.bodies || b >= s.bodies || a == b) return false;
  }
  return true;
}

/// Body field f of a rigid view (Arrays' order).
template <class T>
T*& body_field(BodyView<T>& b, int f) {
  T** const fields[17] = {&b.inv_mass, &b.inv_inertia.x, &b.inv_inertia.y, &b.inv_inertia.z, &b.q.w, &b.q.x,
                          &b.q.y,      &b.q.z,           &b.p.x,           &b.p.y,           &b.p.z, &b.v.x,
                          &b.v.y,      &b.v.z,           &b.w.x,           &b.w.y,           &b.w.z};
  return *fields[f];
}

/// The body fields each model's view reads (Arrays' order).
bool model_reads_field(Model model, int f) {
  switch (model) {
    case Model::particle:
      return f == 0 || (f >= 11 && f <= 13);
    case Model::sphere:
      return f <= 1 || f >= 8;
    case Model::rigid:
      break;
  }
  return true;
}

/// validate() of the view model m solves.
template <class T>
Validation validate_as(Model m, const BodyView<T>& b, const ContactView<T>& c, const ImpulseView<T>& j) {
  switch (m) {
    case Model::particle:
      return validate(particle_view(b), c, j);
    case Model::sphere:
      return validate(sphere_view(b), c, j);
    case Model::rigid:
      break;
  }
  return validate(b, c, j);
}

/// Caller-owned arrays with the input's null array and impulse count, and
/// the views on them.
template <class T>
struct Views {
  Arrays<T> arrays;
  BodyView<T> bodies;
  ContactView<T> contacts;
  ImpulseView<T> impulses;

  Views(const Input& in, T j_fill) : arrays(in.raw) {
    const std::size_t n = in.raw.contacts;
    const std::size_t j_count = n + static_cast<std::size_t>(static_cast<std::ptrdiff_t>(in.impulse_delta));
    for (auto& x : arrays.j) x.assign(std::max(n, j_count), j_fill);
    bodies = arrays.bodies();
    contacts = arrays.contacts(in.raw);
    impulses = arrays.impulses();
    impulses.count = j_count;
    const int null = in.null;
    if (null >= 0 && null < 17) body_field(bodies, null) = nullptr;
    if (null == kNullA) contacts.a = nullptr;
    if (null == kNullB) contacts.b = nullptr;
    const T** const c[6] = {&contacts.c.x, &contacts.c.y, &contacts.c.z, &contacts.n.x, &contacts.n.y, &contacts.n.z};
    if (null >= kNullCx && null <= kNullNz) *c[null - kNullCx] = nullptr;
    T** const j[3] = {&impulses.j.x, &impulses.j.y, &impulses.j.z};
    if (null >= kNullJx && null <= kNullJz) *j[null - kNullJx] = nullptr;
  }
  Views(const Views&) = delete;
  Views& operator=(const Views&) = delete;
};

/// The bytes of every array a call may write (bodies and J).
template <class T>
std::vector<unsigned char> written_bytes(const Arrays<T>& x) {
  std::vector<unsigned char> bytes;
  for (const auto& f : x.body) {
    const auto* p = reinterpret_cast<const unsigned char*>(f.data());
    bytes.insert(bytes.end(), p, p + f.size() * sizeof(T));
  }
  for (const auto& f : x.j) {
    const auto* p = reinterpret_cast<const unsigned char*>(f.data());
    bytes.insert(bytes.end(), p, p + f.size() * sizeof(T));
  }
  return bytes;
}

/// A NaN no arithmetic produces (arithmetic gives the default quiet NaN):
/// J is filled with it before a solve, so a slot that keeps it was not
/// written.
template <class T>
T unwritten() {
  if constexpr (sizeof(T) == 4) {
    const std::uint32_t bits = 0x7fc0dead;
    T x;
    std::memcpy(&x, &bits, sizeof x);
    return x;
  } else {
    const std::uint64_t bits = 0x7ff800000000deadULL;
    T x;
    std::memcpy(&x, &bits, sizeof x);
    return x;
  }
}

template <class T>
bool same_bits(T x, T y) {
  return std::memcmp(&x, &y, sizeof(T)) == 0;
}

/// Runs `f`; true when it returned, false when it threw
/// std::invalid_argument or std::length_error with a message. Any other
/// exception is a failure.
template <class F>
bool returns(const char* what, F&& f, std::string* message = nullptr) {
  try {
    f();
    return true;
  } catch (const std::invalid_argument& e) {
    if (e.what()[0] == '\0') fail(std::string(what) + ": std::invalid_argument without a message");
    if (message) *message = e.what();
  } catch (const std::length_error& e) {
    if (e.what()[0] == '\0') fail(std::string(what) + ": std::length_error without a message");
    if (message) *message = e.what();
  } catch (const std::exception& e) {
    fail(std::string(what) + ": unexpected exception: " + e.what());
  }
  return false;
}

/// One solve's outcome, to compare across paths and layouts: the bodies' v
/// and w and J, as bytes, or nothing when it threw.
template <class T>
struct Outcome {
  bool ran = false;
  std::vector<unsigned char> bytes;
};

template <class T>
class Run {
 public:
  explicit Run(const Input& in) : in_(in), n_(in.raw.contacts), body_count_(in.raw.bodies) {}

  void operator()() {
    Views<T> start(in_, unwritten<T>());
    check_validate(start);
    check_build(start);
    if (!indices_in_range(in_.raw)) {
      // No schedule exists for these contacts; the one-shot solve refuses them.
      for (const Accuracy accuracy : {Accuracy::fast, Accuracy::accurate}) {
        for (const Path path : {Path::scalar, Path::simd}) {
          if (check_one_shot(accuracy, path).ran) fail("collide::solve ran with bad indices");
        }
      }
      return;
    }

    // The schedule of the scene's own indices and inverse masses (whatever
    // array this input nulls): every solve below gets one of the right counts.
    Arrays<T> whole(in_.raw);
    const BodyView<T> whole_bodies = whole.bodies();
    const ContactView<T> whole_contacts = whole.contacts(in_.raw);
    Schedule schedule;
    if (!returns("Schedule::build", [&] { schedule.build(whole_contacts, whole_bodies); })) {
      fail("Schedule::build refused a scene of valid indices and arrays");
    }
    Schedule fewer;  // built for one contact fewer: every solve must refuse it
    if (n_ > 0) fewer.build(contact_slice(whole_contacts, 0, n_ - 1), whole_bodies);

    for (const Accuracy accuracy : {Accuracy::fast, Accuracy::accurate}) {
      std::array<Outcome<T>, 3> by_model{};  // particle, sphere, rigid: the first result of each
      std::array<Outcome<T>, 2> one_shot{};  // scalar, simd
      for (const Path path : {Path::scalar, Path::simd}) {
        solves(accuracy, path, schedule, by_model);
        if (n_ > 0 && path == Path::simd) refuses_other_counts(accuracy, fewer);
        one_shot[path == Path::simd] = check_one_shot(accuracy, path);
      }
      // The one-shot solve gives the bytes of Solver::solve with
      // choose_model()'s model.
      if (rigid_valid_ && one_shot[0].ran) {
        const Outcome<T>& same = by_model[static_cast<int>(chosen_)];
        if (!same.ran) fail("no Solver::solve ran with the chosen model");
        for (const Outcome<T>& o : one_shot) {
          if (o.bytes != same.bytes) fail("collide::solve() differs from Solver::solve with choose_model()'s model");
        }
      }
    }
  }

 private:
  /// validate() on the three SoA views and (where the arrays allow packing)
  /// the packed ones: never throws, says why it rejects, never accepts what
  /// would leave the arrays.
  void check_validate(Views<T>& v) {
    const Validation rigid = validate(v.bodies, v.contacts, v.impulses);
    const Validation sphere = validate(sphere_view(v.bodies), v.contacts, v.impulses);
    const Validation particle = validate(particle_view(v.bodies), v.contacts, v.impulses);
    for (const Validation* x : {&rigid, &sphere, &particle}) {
      if (!*x && x->message.empty()) fail("validate() rejected without saying why");
    }
    const bool structural = indices_in_range(in_.raw) && in_.impulse_delta == 0;
    for (const Model m : {Model::particle, Model::sphere, Model::rigid}) {
      const Validation& x = m == Model::rigid ? rigid : m == Model::sphere ? sphere : particle;
      if (x && (!structural || reads_null(m))) {
        fail(std::string("validate() accepted a ") + to_string(m) + " view with bad indices or arrays");
      }
    }
    rigid_valid_ = static_cast<bool>(rigid);
    valid_[static_cast<int>(Model::particle)] = static_cast<bool>(particle);
    valid_[static_cast<int>(Model::sphere)] = static_cast<bool>(sphere);
    valid_[static_cast<int>(Model::rigid)] = rigid_valid_;
    if (rigid_valid_) chosen_ = choose_model(v.bodies, v.contacts);
    // Packed records get the verdict of their SoA view.
    if (!packable(Model::rigid)) return;
    PackedBuffer<PackedRigid<T>> r(body_count_);
    PackedBuffer<PackedSphere<T>> s(body_count_);
    PackedBuffer<PackedParticle<T>> p(body_count_);
    pack(v.bodies, packed_view(r));
    pack(sphere_view(v.bodies), packed_view(s));
    pack(particle_view(v.bodies), packed_view(p));
    if (static_cast<bool>(validate(packed_view(r), v.contacts, v.impulses)) != static_cast<bool>(rigid) ||
        static_cast<bool>(validate(packed_view(s), v.contacts, v.impulses)) != static_cast<bool>(sphere) ||
        static_cast<bool>(validate(packed_view(p), v.contacts, v.impulses)) != static_cast<bool>(particle)) {
      fail("validate() of packed records differs from that of their SoA view");
    }
  }

  /// Schedule::build on the input's views: throws exactly when an index is
  /// bad or an array it reads is null, and is empty then.
  void check_build(Views<T>& v) {
    const bool arrays = !(n_ > 0 && (in_.null == kNullA || in_.null == kNullB)) && !(body_count_ > 0 && in_.null == 0);
    const bool ok = indices_in_range(in_.raw) && arrays;
    for (const int threads : {1, 2}) {
      Schedule s;
      const bool built = returns("Schedule::build", [&] { s.build(v.contacts, v.bodies, threads); });
      if (built != ok) fail(built ? "Schedule::build accepted a bad index or a null array" : "Schedule::build refused");
      if (!built && (s.contact_count() != 0 || s.body_count() != 0 || s.batch_count() != 0)) {
        fail("Schedule::build threw and left a schedule behind");
      }
      if (built && (s.contact_count() != n_ || s.body_count() != body_count_)) fail("Schedule counts");
    }
  }

  /// The view of model m reads an array this input nulls (with its count > 0).
  [[nodiscard]] bool reads_null(Model m) const {
    const int null = in_.null;
    if (null < 0) return false;
    if (null < 17) return body_count_ > 0 && model_reads_field(m, null);
    if (null == kNullRecords || null == kNullRigidInvMass) return false;  // SoA views have none
    if (null >= kNullCx && null <= kNullCz) return n_ > 0 && m != Model::particle;
    return n_ > 0;  // a, b, n, J
  }
  /// The SoA view of model m can be packed (pack() reads every field).
  [[nodiscard]] bool packable(Model m) const {
    return !(in_.null >= 0 && in_.null < 17 && body_count_ > 0 && model_reads_field(m, in_.null));
  }
  [[nodiscard]] bool must_refuse(Model m) const { return in_.impulse_delta != 0 || reads_null(m); }

  /// Checks a solve of model m that ran on `out`: J written, nothing but v
  /// and w changed, immovable bodies untouched, results that still pass
  /// validate(); returns the bytes to compare with the other runs.
  Outcome<T> accepted(Model m, Views<T>& out, const Arrays<T>& before) {
    const Arrays<T>& a = out.arrays;
    const std::size_t fields[] = {11, 12, 13, 14, 15, 16};
    for (std::size_t f = 0; f < 17; ++f) {
      const bool written = f >= 11 && model_reads_field(m, static_cast<int>(f));
      for (std::size_t i = 0; i < body_count_; ++i) {
        const bool immovable = before.body[0][i] == T(0);
        if ((!written || immovable) && !same_bits(a.body[f][i], before.body[f][i])) {
          fail(std::string("a ") + to_string(m) + " solve wrote a field it must not (field " + std::to_string(f) +
               ", body " + std::to_string(i) + ")");
        }
      }
    }
    for (const auto& j : a.j) {
      for (std::size_t k = 0; k < n_; ++k) {
        if (same_bits(j[k], unwritten<T>())) fail("a solve left J[" + std::to_string(k) + "] unwritten");
      }
    }
    const Validation after = validate_as(m, out.bodies, out.contacts, out.impulses);
    if (!after) {
      const bool velocity = after.message.rfind("bodies.v.", 0) == 0 || after.message.rfind("bodies.w.", 0) == 0;
      if (!velocity || fuzz::moderate(in_.raw)) {
        fail("results of a valid " + std::string(to_string(m)) + " solve fail validate(): " + after.message);
      }
    }
    if (fuzz::moderate(in_.raw)) {
      for (const auto& j : a.j) {
        for (std::size_t k = 0; k < n_; ++k) {
          if (!std::isfinite(j[k])) fail("a non-finite impulse from moderate input");
        }
      }
    }
    Outcome<T> o;
    o.ran = true;
    for (const std::size_t f : fields) {
      const auto* p = reinterpret_cast<const unsigned char*>(a.body[f].data());
      o.bytes.insert(o.bytes.end(), p, p + a.body[f].size() * sizeof(T));
    }
    for (const auto& j : a.j) {
      const auto* p = reinterpret_cast<const unsigned char*>(j.data());
      o.bytes.insert(o.bytes.end(), p, p + n_ * sizeof(T));
    }
    return o;
  }

  /// One Solver::solve call of model m on a fresh copy of the input: refuses
  /// exactly when it must, then writes nothing; otherwise checked by
  /// accepted() when validate() accepted the view, and compared with the
  /// model's first result.
  template <class Call>
  void one_solve(const char* what, Model m, Call&& call, std::array<Outcome<T>, 3>& by_model) {
    Views<T> out(in_, unwritten<T>());
    const Arrays<T> before = out.arrays;
    const bool ran = returns(what, [&] { call(out); });
    if (ran == must_refuse(m)) {
      fail(std::string(what) + (ran ? ": solved what it must refuse" : ": refused a solve it must run"));
    }
    if (!ran) {
      if (written_bytes(out.arrays) != written_bytes(before)) fail(std::string(what) + ": refused but wrote");
      return;
    }
    if (!valid_[static_cast<int>(m)]) return;  // values validate() rejects: memory safety only
    const Outcome<T> o = accepted(m, out, before);
    Outcome<T>& first = by_model[static_cast<int>(m)];
    if (!first.ran) {
      first = o;
    } else if (first.bytes != o.bytes) {
      fail(std::string(what) + ": results differ between paths or layouts");
    }
  }

  void solves(Accuracy accuracy, Path path, const Schedule& schedule, std::array<Outcome<T>, 3>& by_model) {
    SolverOptions o;
    o.path = path;
    o.threads = 1;
    o.block = 8;
    o.accuracy = accuracy;
    for (const BodyLayout layout : {BodyLayout::soa, BodyLayout::packed}) {
      o.layout = layout;
      const Solver& solver = fuzz::cached_solver(o);
      one_solve(
          "solve(BodyView)", Model::rigid,
          [&](Views<T>& v) { solver.solve(v.bodies, v.contacts, v.impulses, schedule); }, by_model);
      one_solve(
          "solve(SphereView)", Model::sphere,
          [&](Views<T>& v) { solver.solve(sphere_view(v.bodies), v.contacts, v.impulses, schedule); }, by_model);
      one_solve(
          "solve(ParticleView)", Model::particle,
          [&](Views<T>& v) { solver.solve(particle_view(v.bodies), v.contacts, v.impulses, schedule); }, by_model);
      // The model overload: rigid always fits; a smaller model only where
      // choose_model() picked it (debug builds assert the fit) or where the
      // call must be refused before that.
      for (const Model m : {Model::particle, Model::sphere, Model::rigid}) {
        if (m != Model::rigid && !(rigid_valid_ && m == chosen_) && !must_refuse(m)) continue;
        one_solve(
            "solve(Model, BodyView)", m,
            [&](Views<T>& v) { solver.solve(m, v.bodies, v.contacts, v.impulses, schedule); }, by_model);
      }
    }
    // The caller's packed records (pack()), solved in place; their v and w
    // are unpacked into the SoA arrays to compare.
    const Solver& solver = fuzz::cached_solver(o);
    packed_solve<PackedRigid<T>>(Model::rigid, solver, schedule, by_model);
    packed_solve<PackedSphere<T>>(Model::sphere, solver, schedule, by_model);
    packed_solve<PackedParticle<T>>(Model::particle, solver, schedule, by_model);
  }

  template <class Record>
  void packed_solve(Model m, const Solver& solver, const Schedule& schedule, std::array<Outcome<T>, 3>& by_model) {
    if (!packable(m)) return;
    const auto soa = [](Views<T>& v) {
      if constexpr (std::is_same_v<Record, PackedRigid<T>>) {
        return v.bodies;
      } else if constexpr (std::is_same_v<Record, PackedSphere<T>>) {
        return sphere_view(v.bodies);
      } else {
        return particle_view(v.bodies);
      }
    };
    const bool null_records = in_.null == kNullRecords && body_count_ > 0;
    const bool null_inv_mass =
        std::is_same_v<Record, PackedRigid<T>> && in_.null == kNullRigidInvMass && body_count_ > 0;
    const char* what = std::is_same_v<Record, PackedRigid<T>>    ? "solve(PackedView<PackedRigid>)"
                       : std::is_same_v<Record, PackedSphere<T>> ? "solve(PackedView<PackedSphere>)"
                                                                 : "solve(PackedView<PackedParticle>)";
    Views<T> out(in_, unwritten<T>());
    const Arrays<T> before = out.arrays;
    PackedBuffer<Record> records(body_count_);
    PackedView<Record> view = packed_view(records);
    pack(soa(out), view);
    if (null_records) view.bodies = nullptr;
    if constexpr (std::is_same_v<Record, PackedRigid<T>>) {
      if (null_inv_mass) view.inv_mass = nullptr;
    }
    const bool refuse = must_refuse(m) || null_records || null_inv_mass;
    const bool ran = returns(what, [&] { solver.solve(view, out.contacts, out.impulses, schedule); });
    if (ran == refuse)
      fail(std::string(what) + (ran ? ": solved what it must refuse" : ": refused a solve it must run"));
    if (!ran) {
      if (written_bytes(out.arrays) != written_bytes(before)) fail(std::string(what) + ": refused but wrote J");
      return;
    }
    unpack_velocities(packed_view(records), soa(out));
    if (!valid_[static_cast<int>(m)]) return;
    const Outcome<T> o = accepted(m, out, before);
    Outcome<T>& first = by_model[static_cast<int>(m)];
    if (!first.ran) {
      first = o;
    } else if (first.bytes != o.bytes) {
      fail(std::string(what) + ": results differ from the SoA views'");
    }
  }

  /// Every overload refuses a schedule built for one contact fewer, and
  /// writes nothing.
  void refuses_other_counts(Accuracy accuracy, const Schedule& fewer) {
    SolverOptions o;
    o.path = Path::simd;
    o.threads = 1;
    o.block = 8;
    o.accuracy = accuracy;
    const Solver& solver = fuzz::cached_solver(o);
    Views<T> out(in_, unwritten<T>());
    const std::vector<unsigned char> before = written_bytes(out.arrays);
    const auto refused = [&](const char* what, auto&& call) {
      std::string message;
      if (returns(what, call, &message)) fail(std::string(what) + ": ran with a schedule of other counts");
      if (written_bytes(out.arrays) != before) fail(std::string(what) + ": refused but wrote");
    };
    refused("solve(BodyView)", [&] { solver.solve(out.bodies, out.contacts, out.impulses, fewer); });
    refused("solve(SphereView)", [&] { solver.solve(sphere_view(out.bodies), out.contacts, out.impulses, fewer); });
    refused("solve(ParticleView)", [&] { solver.solve(particle_view(out.bodies), out.contacts, out.impulses, fewer); });
    for (const Model m : {Model::particle, Model::sphere, Model::rigid}) {
      refused("solve(Model, BodyView)", [&] { solver.solve(m, out.bodies, out.contacts, out.impulses, fewer); });
    }
    PackedView<PackedSphere<T>> none{body_count_, nullptr};
    refused("solve(PackedView<PackedSphere>)", [&] { solver.solve(none, out.contacts, out.impulses, fewer); });
  }

  /// collide::solve(): validate()'s verdict and message, nothing written on
  /// a refusal.
  Outcome<T> check_one_shot(Accuracy accuracy, Path path) {
    SolverOptions o;
    o.path = path;
    o.threads = 1;
    o.block = 8;
    o.accuracy = accuracy;
    Views<T> out(in_, unwritten<T>());
    const Arrays<T> before = out.arrays;
    const Validation v = validate(out.bodies, out.contacts, out.impulses);
    std::string message;
    const bool ran = returns(
        "collide::solve", [&] { collide::solve(out.bodies, out.contacts, out.impulses, o); }, &message);
    if (ran != static_cast<bool>(v)) fail(ran ? "collide::solve ran on invalid input" : "collide::solve refused");
    if (!ran) {
      if (message != "collide::solve: " + v.message) fail("collide::solve: not validate()'s message: " + message);
      if (written_bytes(out.arrays) != written_bytes(before)) fail("collide::solve refused but wrote");
      return {};
    }
    return accepted(chosen_, out, before);
  }

  const Input& in_;
  std::size_t n_;
  std::size_t body_count_;
  bool rigid_valid_ = false;
  std::array<bool, 3> valid_{};  // validate() of the particle, sphere, rigid SoA view
  Model chosen_ = Model::rigid;  // choose_model(), when the rigid view is valid
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const Input input = decode(data, size);
  Run<float>{input}();
  Run<double>{input}();
  return 0;
}
