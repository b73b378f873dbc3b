// test_source_page.cpp - the source page's apparent-mass formula, in the
// page's own convention, against the collision law (kernel and reference).
//
// What this proves
// ----------------
// The page ("Physics - Collision in 3 dimensions") writes torque as
// T = F x R and the acceleration of a body point as A = R x a, so its
// angular vectors are the negatives of the project's (the law uses r x F and
// w x r). page_collision() below transcribes the page's C++ test program
// step by step in that convention: the approach speed
// Vba = (Vb + Rb x Wb - Va - Ra x Wa) . N, the lever arms N x Ra and (-N) x Rb
// (the page's "NbxRb computed with -N"), rotated into each body's local frame
// by the transpose of its orientation and divided component-wise by the radii
// of gyration r = sqrt(I / M) to give Ha and Hb, and the perfectly elastic
// impulse Ja = 2 Vba / ((1 + |Hb|^2) / Mb + (1 + |Ha|^2) / Ma), followed by
// the page's velocity updates dV = (Ja / M) N and dW = O ((Ja / M) H / r).
// On 10k random cases drawn the page's way (every number (rand() % 2000) /
// 100, orientations as rotation vectors, redrawn until the bodies approach):
// * the page's Ja equals |J| of the law with e = 1, mu = 0, to 1e-12
//   relative, for the double kernel (scalar and SIMD) and the double
//   reference;
// * the page's Vba is the law's -vn;
// * the page's final velocities, with W negated into the project's
//   convention, equal the law's, to 1e-12 of the velocity scale.
// Cases whose approach speed is below 1e-3 of the speed scale are redrawn as
// well: there the impulse is a difference of nearly equal velocities, and
// both evaluations only agree to eps * speed_scale / Vba, which measures
// rounding rather than the formula.
#include <array>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "collide/eval/reference.hpp"
#include "collide/io/scene.hpp"
#include "collide/solve.hpp"
#include "support/solve_helpers.hpp"

namespace collide::test {
namespace {

using Vec = std::array<double, 3>;
using Mat = std::array<Vec, 3>;  // row-major

Vec operator+(const Vec& a, const Vec& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
Vec operator-(const Vec& a, const Vec& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Vec operator*(double s, const Vec& a) { return {s * a[0], s * a[1], s * a[2]}; }
Vec operator-(const Vec& a) { return {-a[0], -a[1], -a[2]}; }
double dot(const Vec& a, const Vec& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Vec cross(const Vec& a, const Vec& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double norm(const Vec& a) { return std::sqrt(dot(a, a)); }
Vec times(const Mat& m, const Vec& v) { return {dot(m[0], v), dot(m[1], v), dot(m[2], v)}; }
Vec transpose_times(const Mat& m, const Vec& v) {
  return {m[0][0] * v[0] + m[1][0] * v[1] + m[2][0] * v[2], m[0][1] * v[0] + m[1][1] * v[1] + m[2][1] * v[2],
          m[0][2] * v[0] + m[1][2] * v[1] + m[2][2] * v[2]};
}

/// The page's orientation: a rotation vector Q (angle |Q| about Q / |Q|).
Mat rotation_matrix(const Vec& q) {
  const double angle = norm(q);
  const Vec k = (1 / angle) * q;
  const double c = std::cos(angle), s = std::sin(angle), t = 1 - c;
  return {{{t * k[0] * k[0] + c, t * k[0] * k[1] - s * k[2], t * k[0] * k[2] + s * k[1]},
           {t * k[0] * k[1] + s * k[2], t * k[1] * k[1] + c, t * k[1] * k[2] - s * k[0]},
           {t * k[0] * k[2] - s * k[1], t * k[1] * k[2] + s * k[0], t * k[2] * k[2] + c}}};
}
/// The same rotation as a unit quaternion (w, x, y, z), for the law.
std::array<double, 4> quaternion(const Vec& q) {
  const double angle = norm(q);
  const double s = std::sin(angle / 2) / angle;
  return {std::cos(angle / 2), s * q[0], s * q[1], s * q[2]};
}

/// One body as the page's program holds it (page convention: W = -w).
struct PageBody {
  double M;
  Vec I;  // principal moments
  Vec Q;  // orientation, rotation vector
  Vec V, W;
  Vec R;  // centre of mass to contact point
};

struct PageResult {
  double vba;          // approach speed
  double ja;           // impulse, along N on A
  Vec va, vb, wa, wb;  // final velocities, page convention
};

/// The page's program, transcribed (names as on the page).
PageResult page_collision(const PageBody& A, const PageBody& B, const Vec& N) {
  const Mat Oa = rotation_matrix(A.Q), Ob = rotation_matrix(B.Q);
  const Vec ra{std::sqrt(A.I[0] / A.M), std::sqrt(A.I[1] / A.M), std::sqrt(A.I[2] / A.M)};
  const Vec rb{std::sqrt(B.I[0] / B.M), std::sqrt(B.I[1] / B.M), std::sqrt(B.I[2] / B.M)};
  // (Vb + (Rb x Wb) - Va - (Ra x Wa)) . N
  const double vba = dot(B.V + cross(B.R, B.W) - A.V - cross(A.R, A.W), N);
  const Vec NaxRa = cross(N, A.R);                 // global frame
  const Vec NbxRb = cross(-N, B.R);                // global frame, with -N
  const Vec NaaxRaa = transpose_times(Oa, NaxRa);  // local frame of A
  const Vec NbbxRbb = transpose_times(Ob, NbxRb);
  const Vec Ha{NaaxRaa[0] / ra[0], NaaxRaa[1] / ra[1], NaaxRaa[2] / ra[2]};
  const Vec Hb{NbbxRbb[0] / rb[0], NbbxRbb[1] / rb[1], NbbxRbb[2] / rb[2]};
  const double Ja = 2.0 * vba / ((1 + dot(Hb, Hb)) / B.M + (1 + dot(Ha, Ha)) / A.M);
  const Vec dVa = (Ja / A.M) * N;
  const Vec dVb = (Ja / B.M) * (-N);
  const Vec dWaa{(Ja / A.M) * (Ha[0] / ra[0]), (Ja / A.M) * (Ha[1] / ra[1]), (Ja / A.M) * (Ha[2] / ra[2])};
  const Vec dWbb{(Ja / B.M) * (Hb[0] / rb[0]), (Ja / B.M) * (Hb[1] / rb[1]), (Ja / B.M) * (Hb[2] / rb[2])};
  return {vba, Ja, A.V + dVa, B.V + dVb, A.W + times(Oa, dWaa), B.W + times(Ob, dWbb)};
}

/// The page's draws: #define RandomizeDby2(D) { D = (rand() % 2000)/100.0;}
/// (0 excluded, since masses and moments divide).
class PageRandom {
 public:
  explicit PageRandom(std::uint64_t seed) : g_(seed) {}
  double d() { return static_cast<double>(g_() % 1999 + 1) / 100.0; }
  Vec v() { return {d(), d(), d()}; }

 private:
  std::mt19937_64 g_;
};

struct PageCase {
  PageBody a, b;
  Vec n;
  Vec c;  // contact point (the page needs only Ra, Rb; the law needs c, p)
};

std::vector<PageCase> draw_cases(std::size_t count, std::uint64_t seed) {
  PageRandom rnd(seed);
  std::vector<PageCase> out;
  while (out.size() < count) {
    PageCase k;
    for (PageBody* b : {&k.a, &k.b}) {
      b->V = rnd.v();
      b->W = rnd.v();
    }
    k.a.M = rnd.d();
    k.b.M = rnd.d();
    k.a.I = rnd.v();
    k.b.I = rnd.v();
    k.a.Q = rnd.v();
    k.b.Q = rnd.v();
    k.n = rnd.v();
    k.n = (1 / norm(k.n)) * k.n;
    k.a.R = rnd.v();
    k.b.R = rnd.v();
    k.c = rnd.v();
    const PageResult r = page_collision(k.a, k.b, k.n);
    const double speed = norm(k.a.V) + norm(k.a.W) * norm(k.a.R) + norm(k.b.V) + norm(k.b.W) * norm(k.b.R);
    if (r.ja <= 0 || r.vba < 1e-3 * speed) continue;  // the page: if(Ja < 0.0) goto START;
    out.push_back(k);
  }
  return out;
}

/// The cases as a pairs scene of the law: body 2k = A, 2k+1 = B, p = c - R,
/// q from the rotation vector, w = -W (project convention), e = 1, mu = 0.
Scene<double> to_scene(const std::vector<PageCase>& cases) {
  Scene<double> s;
  for (std::size_t k = 0; k < cases.size(); ++k) {
    const PageCase& pc = cases[k];
    for (const PageBody* pb : {&pc.a, &pc.b}) {
      BodyRecord<double> b;
      b.m = pb->M;
      const auto q = quaternion(pb->Q);
      for (int i = 0; i < 3; ++i) {
        b.I[i] = pb->I[i];
        b.p[i] = pc.c[i] - pb->R[i];
        b.v[i] = pb->V[i];
        b.w[i] = -pb->W[i];
      }
      for (int i = 0; i < 4; ++i) b.q[i] = q[i];
      s.bodies.push_back(b);
    }
    ContactRecord<double> c;
    c.a = static_cast<BodyIndex>(2 * k);
    c.b = static_cast<BodyIndex>(2 * k + 1);
    for (int i = 0; i < 3; ++i) {
      c.c[i] = pc.c[i];
      c.n[i] = pc.n[i];
    }
    c.e = 1;
    c.mu = 0;
    s.contacts.push_back(c);
  }
  return s;
}

void expect_matches_page(const std::vector<PageCase>& cases, const BodyBuffer<double>& after,
                         const ImpulseBuffer<double>& j, const std::string& label) {
  SCOPED_TRACE(label);
  constexpr double kRel = 1e-12;
  const BodyView<const double> b = after.view();
  const auto jv = j.view();
  std::size_t failures = 0;
  double worst_j = 0, worst_v = 0;
  for (std::size_t k = 0; k < cases.size(); ++k) {
    const PageCase& pc = cases[k];
    const PageResult page = page_collision(pc.a, pc.b, pc.n);
    const Vec J{jv.j.x[k], jv.j.y[k], jv.j.z[k]};
    const double rel_j = std::fabs(norm(J) - page.ja) / page.ja;
    // J is along +N (on A).
    const double along = dot(J, pc.n) / norm(J);
    const std::size_t ia = 2 * k, ib = 2 * k + 1;
    const Vec va{b.v.x[ia], b.v.y[ia], b.v.z[ia]}, vb{b.v.x[ib], b.v.y[ib], b.v.z[ib]};
    const Vec wa{b.w.x[ia], b.w.y[ia], b.w.z[ia]}, wb{b.w.x[ib], b.w.y[ib], b.w.z[ib]};
    const double vscale = norm(pc.a.V) + norm(pc.b.V) + norm(pc.a.W) + norm(pc.b.W) + page.ja / pc.a.M +
                          page.ja / pc.b.M + norm(page.wa) + norm(page.wb);
    const double rel_v =
        std::max({norm(va - page.va), norm(vb - page.vb), norm(wa + page.wa), norm(wb + page.wb)}) / vscale;
    worst_j = std::max(worst_j, rel_j);
    worst_v = std::max(worst_v, rel_v);
    if ((rel_j > kRel || rel_v > kRel || along < 1 - 1e-12) && failures++ < 5) {
      ADD_FAILURE() << "case " << k << ": page Ja " << page.ja << ", |J| " << norm(J) << " (rel " << rel_j
                    << "), velocities rel " << rel_v << ", J.N/|J| " << along;
    }
  }
  EXPECT_EQ(failures, 0u);
  std::cout << "[source page] " << label << ": worst |J| rel " << worst_j << ", worst velocity rel " << worst_v
            << " (tolerance 1e-12)" << std::endl;
}

TEST(SourcePage, ApparentMassImpulseEqualsLawWithElasticRestitution) {
  const std::vector<PageCase> cases = draw_cases(10000, 1998);
  const Scene<double> scene = to_scene(cases);
  for (const Path path : {Path::scalar, Path::simd}) {
    BodyBuffer<double> after = scene.bodies;
    const ImpulseBuffer<double> j = kernel_solve(after, scene.contacts.view(), options_for(path, 2));
    expect_matches_page(cases, after, j, std::string("kernel double ") + to_string(path));
  }
  BodyBuffer<double> after = scene.bodies;
  std::vector<ReferenceContact<double>> diag;
  const ImpulseBuffer<double> j = reference(after, scene.contacts.view(), &diag);
  expect_matches_page(cases, after, j, "reference double");
  // The page's approach speed is the law's -vn.
  for (std::size_t k = 0; k < cases.size(); ++k) {
    const double vba = page_collision(cases[k].a, cases[k].b, cases[k].n).vba;
    ASSERT_NEAR(-diag[k].vn, vba, 1e-12 * diag[k].speed_scale) << "case " << k;
  }
}

// The convention matters: reading the page's W as the project's w (no sign
// flip) gives a different impulse on these cases, so the test above really
// checks the conversion.
TEST(SourcePage, ConventionFlipIsNotANoOp) {
  const std::vector<PageCase> cases = draw_cases(200, 7);
  std::size_t differ = 0;
  for (const PageCase& pc : cases) {
    PageBody a = pc.a, b = pc.b;
    a.W = -a.W;
    b.W = -b.W;
    const double flipped = page_collision(a, b, pc.n).ja;
    differ += std::fabs(flipped - page_collision(pc.a, pc.b, pc.n).ja) > 1e-6;
  }
  EXPECT_GT(differ, cases.size() * 9 / 10);
}

}  // namespace
}  // namespace collide::test
