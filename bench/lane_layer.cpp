// lane_layer.cpp - how the lane layer was chosen
// (docs/decisions/0003-the-lane-layer.md). The same arithmetic, the inverse effective mass of one body's
// lever arm and the normal impulse over SoA arrays,
//     h = R^T (r x n),  K = 1/m + h . (invI * h),  j = -(1 + e) vn / K,
// written once over a lane type and run with three candidates:
//   * std::experimental::simd (native ABI): what the kernels use;
//   * Eigen::Array<T, W, 1>: Eigen fixed-size arrays;
//   * raw AVX2 intrinsics behind a 20-line wrapper (float only).
// If the first is as fast as raw intrinsics, the portable, width-generic
// choice costs nothing. Run: build/bench/collide_lane_layer.
#include <benchmark/benchmark.h>

#include <immintrin.h>
#include <Eigen/Core>
#include <experimental/simd>
#include <random>
#include <vector>

namespace {

namespace stdx = std::experimental;

constexpr std::size_t kN = 1 << 14;  // 16k elements x 17 arrays x 4 B: in L2

template <class T>
struct Soa {
  std::vector<T> f[17];
  std::vector<T> out;
  Soa() {
    std::mt19937 g(7);
    std::uniform_real_distribution<T> u(T(0.1), T(2));
    for (auto& v : f) {
      v.resize(kN);
      for (auto& x : v) x = u(g);
    }
    out.resize(kN);
  }
};

// Lane adaptors: load, store, and the arithmetic through operators.
struct StdxFloat {
  using V = stdx::native_simd<float>;
  static constexpr std::size_t W = V::size();
  static V load(const float* p) { return V(p, stdx::element_aligned); }
  static void store(const V& v, float* p) { v.copy_to(p, stdx::element_aligned); }
  static V splat(float x) { return V(x); }
};
struct EigenFloat {
  using V = Eigen::Array<float, 8, 1>;
  static constexpr std::size_t W = 8;
  static V load(const float* p) { return Eigen::Map<const V>(p); }
  static void store(const V& v, float* p) { Eigen::Map<V>{p} = v; }
  static V splat(float x) { return V::Constant(x); }
};
struct Avx2Float {
  struct V {
    __m256 m;
    V() = default;
    explicit V(float s) : m(_mm256_set1_ps(s)) {}
    explicit V(__m256 x) : m(x) {}
    friend V operator+(V a, V b) { return V(_mm256_add_ps(a.m, b.m)); }
    friend V operator-(V a, V b) { return V(_mm256_sub_ps(a.m, b.m)); }
    friend V operator*(V a, V b) { return V(_mm256_mul_ps(a.m, b.m)); }
    friend V operator/(V a, V b) { return V(_mm256_div_ps(a.m, b.m)); }
  };
  static constexpr std::size_t W = 8;
  static V load(const float* p) { return V(_mm256_loadu_ps(p)); }
  static void store(const V& v, float* p) { _mm256_storeu_ps(p, v.m); }
  static V splat(float x) { return V(x); }
};

template <class L>
void BM_LaneLayer(benchmark::State& state) {
  using V = typename L::V;
  Soa<float> s;
  for (auto _ : state) {
    for (std::size_t i = 0; i < kN; i += L::W) {
      auto ld = [&](int k) { return L::load(s.f[k].data() + i); };
      const V qw = ld(0), qx = ld(1), qy = ld(2), qz = ld(3);
      const V rx = ld(4), ry = ld(5), rz = ld(6), nx = ld(7), ny = ld(8), nz = ld(9);
      const V ix = ld(10), iy = ld(11), iz = ld(12), inv_m = ld(13), e = ld(14), vn = ld(15);
      // rotation matrix from q, r x n, then R^T (r x n)
      const V two = L::splat(2.0f), one = L::splat(1.0f);
      const V r00 = one - two * (qy * qy + qz * qz), r01 = two * (qx * qy - qw * qz), r02 = two * (qx * qz + qw * qy);
      const V r10 = two * (qx * qy + qw * qz), r11 = one - two * (qx * qx + qz * qz), r12 = two * (qy * qz - qw * qx);
      const V r20 = two * (qx * qz - qw * qy), r21 = two * (qy * qz + qw * qx), r22 = one - two * (qx * qx + qy * qy);
      const V cx = ry * nz - rz * ny, cy = rz * nx - rx * nz, cz = rx * ny - ry * nx;
      const V hx = r00 * cx + r10 * cy + r20 * cz, hy = r01 * cx + r11 * cy + r21 * cz,
              hz = r02 * cx + r12 * cy + r22 * cz;
      const V k = inv_m + (hx * (ix * hx) + hy * (iy * hy) + hz * (iz * hz));
      L::store(L::splat(0.0f) - (one + e) * vn / k, s.out.data() + i);
    }
    benchmark::DoNotOptimize(s.out.data());
    benchmark::ClobberMemory();
  }
  state.counters["elements_per_second"] =
      benchmark::Counter(static_cast<double>(kN) * state.iterations(), benchmark::Counter::kIsRate);
}

BENCHMARK_TEMPLATE(BM_LaneLayer, StdxFloat)->Name("LaneLayer/std_experimental_simd");
BENCHMARK_TEMPLATE(BM_LaneLayer, EigenFloat)->Name("LaneLayer/eigen_array8");
BENCHMARK_TEMPLATE(BM_LaneLayer, Avx2Float)->Name("LaneLayer/avx2_intrinsics");

}  // namespace

BENCHMARK_MAIN();
