// transpose_lanes.hpp - lanes filled from rows: the W records of W contacts'
// bodies loaded as vectors and transposed in registers (the packed layout,
// collide/packed.hpp).
//
// Design notes
// ------------
// Filling a vector one lane at a time from W addresses (gather() in
// lanes.hpp) costs W scalar loads and inserts per field, and the compiler
// builds wide vectors from scalars through the stack, where the vector load
// waits for W scalar stores (a failed store-to-load forward): for a rigid
// body, 17 x W inserts per side of a contact. A record keeps a body's values
// together, so W consecutive values of each of the W records are loaded as
// W vectors (one aligned line each) and transposed: value k of every lane
// lands in vector k. The transposes are the textbook ones (unpack, shuffle
// within 128-bit lanes, then exchange 128-bit lanes), written once per
// register width; every ISA without a version here uses the lane-by-lane
// fill, which gives the same values.
//
// Pure data movement: no arithmetic, so the ISA cannot change a bit.
#pragma once

#include <algorithm>
#include <cstddef>
#include <type_traits>

#include "lanes.hpp"

namespace collide::detail {
inline namespace COLLIDE_KERNEL_NS {

#if defined(__SSE2__)
/// The W x W transpose of float registers (W = 4, 8, 16 with SSE, AVX,
/// AVX-512): o[k] lane l = r[l] lane k. Per group of four rows, within each
/// 128-bit lane j, unpack and shuffle give s[k] = column 4j + k of those
/// rows; then 128-bit lanes are exchanged across the groups.
template <std::size_t W, class R>
COLLIDE_LANE_INLINE void transpose_float_registers(const R* r, R* o) {
  R s[W];
  for (std::size_t g = 0; g < W; g += 4) {
    if constexpr (W == 4) {
      const R t0 = _mm_unpacklo_ps(r[g], r[g + 1]), t1 = _mm_unpackhi_ps(r[g], r[g + 1]);
      const R t2 = _mm_unpacklo_ps(r[g + 2], r[g + 3]), t3 = _mm_unpackhi_ps(r[g + 2], r[g + 3]);
      s[g] = _mm_shuffle_ps(t0, t2, 0x44), s[g + 1] = _mm_shuffle_ps(t0, t2, 0xEE);
      s[g + 2] = _mm_shuffle_ps(t1, t3, 0x44), s[g + 3] = _mm_shuffle_ps(t1, t3, 0xEE);
#if defined(__AVX__)
    } else if constexpr (W == 8) {
      const R t0 = _mm256_unpacklo_ps(r[g], r[g + 1]), t1 = _mm256_unpackhi_ps(r[g], r[g + 1]);
      const R t2 = _mm256_unpacklo_ps(r[g + 2], r[g + 3]), t3 = _mm256_unpackhi_ps(r[g + 2], r[g + 3]);
      s[g] = _mm256_shuffle_ps(t0, t2, 0x44), s[g + 1] = _mm256_shuffle_ps(t0, t2, 0xEE);
      s[g + 2] = _mm256_shuffle_ps(t1, t3, 0x44), s[g + 3] = _mm256_shuffle_ps(t1, t3, 0xEE);
#endif
#if defined(__AVX512F__)
    } else {
      const R t0 = _mm512_unpacklo_ps(r[g], r[g + 1]), t1 = _mm512_unpackhi_ps(r[g], r[g + 1]);
      const R t2 = _mm512_unpacklo_ps(r[g + 2], r[g + 3]), t3 = _mm512_unpackhi_ps(r[g + 2], r[g + 3]);
      s[g] = _mm512_shuffle_ps(t0, t2, 0x44), s[g + 1] = _mm512_shuffle_ps(t0, t2, 0xEE);
      s[g + 2] = _mm512_shuffle_ps(t1, t3, 0x44), s[g + 3] = _mm512_shuffle_ps(t1, t3, 0xEE);
#endif
    }
  }
  if constexpr (W == 4) {
    for (std::size_t k = 0; k < 4; ++k) o[k] = s[k];
#if defined(__AVX__)
  } else if constexpr (W == 8) {
    // Column 4j + k: lane j of s[k] (rows 0-3) and of s[4 + k] (rows 4-7).
    for (std::size_t k = 0; k < 4; ++k) {
      o[k] = _mm256_permute2f128_ps(s[k], s[4 + k], 0x20);
      o[4 + k] = _mm256_permute2f128_ps(s[k], s[4 + k], 0x31);
    }
#endif
#if defined(__AVX512F__)
  } else {
    // Column 4j + k: lane j of s[k], s[4 + k], s[8 + k], s[12 + k].
    for (std::size_t k = 0; k < 4; ++k) {
      const R u0 = _mm512_shuffle_f32x4(s[k], s[4 + k], 0x88);  // lanes 0, 2 of each
      const R u1 = _mm512_shuffle_f32x4(s[k], s[4 + k], 0xdd);  // lanes 1, 3 of each
      const R v0 = _mm512_shuffle_f32x4(s[8 + k], s[12 + k], 0x88);
      const R v1 = _mm512_shuffle_f32x4(s[8 + k], s[12 + k], 0xdd);
      o[k] = _mm512_shuffle_f32x4(u0, v0, 0x88);
      o[8 + k] = _mm512_shuffle_f32x4(u0, v0, 0xdd);
      o[4 + k] = _mm512_shuffle_f32x4(u1, v1, 0x88);
      o[12 + k] = _mm512_shuffle_f32x4(u1, v1, 0xdd);
    }
#endif
  }
}
#endif

/// out[k] lane l = rows[l][offset + k], for k < W (rows[l] + offset .. + W - 1
/// must be readable).
template <class V>
COLLIDE_LANE_INLINE void transpose_rows(const typename V::value_type* const* rows, std::size_t offset, V* out) {
  constexpr std::size_t W = V::size();
  using T = typename V::value_type;
#if defined(__SSE2__)
  if constexpr (std::is_same_v<T, float> && (W == 4 || W == 8 || W == 16)) {
    // The W rows as W registers, transposed (transpose_float_registers).
    auto loadu = [](const float* p) COLLIDE_LANE_LAMBDA {
      if constexpr (W == 4) {
        return _mm_loadu_ps(p);
#if defined(__AVX__)
      } else if constexpr (W == 8) {
        return _mm256_loadu_ps(p);
#endif
#if defined(__AVX512F__)
      } else {
        return _mm512_loadu_ps(p);
#endif
      }
    };
    using R = decltype(loadu(rows[0]));
    R r[W];
    for (std::size_t l = 0; l < W; ++l) r[l] = loadu(rows[l] + offset);
    R o[W];
    transpose_float_registers<W>(r, o);
    for (std::size_t k = 0; k < W; ++k) out[k] = V(o[k]);
    return;
  } else if constexpr (std::is_same_v<T, double> && W == 2) {
    const __m128d r0 = _mm_loadu_pd(rows[0] + offset), r1 = _mm_loadu_pd(rows[1] + offset);
    out[0] = V(_mm_unpacklo_pd(r0, r1));
    out[1] = V(_mm_unpackhi_pd(r0, r1));
    return;
#if defined(__AVX__)
  } else if constexpr (std::is_same_v<T, double> && W == 4) {
    __m256d t[4];
    for (std::size_t g = 0; g < 4; g += 2) {
      const __m256d r0 = _mm256_loadu_pd(rows[g] + offset), r1 = _mm256_loadu_pd(rows[g + 1] + offset);
      t[g] = _mm256_unpacklo_pd(r0, r1);      // column 2j of rows g, g+1 in lane j
      t[g + 1] = _mm256_unpackhi_pd(r0, r1);  // column 2j + 1
    }
    for (std::size_t k = 0; k < 2; ++k) {
      out[k] = V(_mm256_permute2f128_pd(t[k], t[2 + k], 0x20));
      out[2 + k] = V(_mm256_permute2f128_pd(t[k], t[2 + k], 0x31));
    }
    return;
#endif
#if defined(__AVX512F__)
  } else if constexpr (std::is_same_v<T, double> && W == 8) {
    __m512d t[8];
    for (std::size_t g = 0; g < 8; g += 2) {
      const __m512d r0 = _mm512_loadu_pd(rows[g] + offset), r1 = _mm512_loadu_pd(rows[g + 1] + offset);
      t[g] = _mm512_unpacklo_pd(r0, r1);      // column 2j of rows g, g+1 in 128-bit lane j
      t[g + 1] = _mm512_unpackhi_pd(r0, r1);  // column 2j + 1
    }
    // u[k]: lanes 0, 2 of t[k] and t[2 + k] (columns k, 4 + k of rows 0-3).
    for (std::size_t k = 0; k < 2; ++k) {
      const __m512d lo03 = _mm512_shuffle_f64x2(t[k], t[2 + k], 0x88);  // columns k, k+4 (lanes 0,2), rows 0-3
      const __m512d hi03 = _mm512_shuffle_f64x2(t[k], t[2 + k], 0xdd);  // columns k+2, k+6, rows 0-3
      const __m512d lo47 = _mm512_shuffle_f64x2(t[4 + k], t[6 + k], 0x88);
      const __m512d hi47 = _mm512_shuffle_f64x2(t[4 + k], t[6 + k], 0xdd);
      out[k] = V(_mm512_shuffle_f64x2(lo03, lo47, 0x88));
      out[4 + k] = V(_mm512_shuffle_f64x2(lo03, lo47, 0xdd));
      out[2 + k] = V(_mm512_shuffle_f64x2(hi03, hi47, 0x88));
      out[6 + k] = V(_mm512_shuffle_f64x2(hi03, hi47, 0xdd));
    }
    return;
#endif
  }
#endif
  for (std::size_t k = 0; k < W; ++k) out[k] = V([&](auto lane) { return rows[lane][offset + k]; });
}

/// How many W x W transposes load_record_values does for N values of a
/// record of S: one per block of W values that fits in the record, except a
/// last block with W/4 values or fewer, which is cheaper lane by lane (a
/// transpose is W loads and about W log2 W shuffles, the lane-by-lane fill W
/// loads and inserts per value). A 17-value record on 16 lanes would take one
/// transpose and value 16 by lanes; the records of collide/packed.hpp (16, 11
/// and 4 values) end on no such short block, and the rule serves any record
/// that does.
template <std::size_t W, std::size_t N, std::size_t S>
inline constexpr std::size_t kRecordTransposes = [] {
  if (W <= 1) return std::size_t{0};
  const std::size_t whole = std::min(S / W, N / W);
  const std::size_t rest = N - whole * W;
  const bool last = rest > W / 4 && (whole + 1) * W <= S;
  return whole + (last ? 1 : 0);
}();

/// out[k] lane l = records[idx[l]].value k, for the first N values of records
/// of S values each: transposes (kRecordTransposes), the rest lane by lane.
template <class V, std::size_t N, std::size_t S, class Index>
COLLIDE_LANE_INLINE void load_record_values(const typename V::value_type* records, const Index* idx, V* out) {
  constexpr std::size_t W = V::size();
  const typename V::value_type* rows[W];
  for (std::size_t l = 0; l < W; ++l) rows[l] = records + static_cast<std::size_t>(idx[l]) * S;
  constexpr std::size_t kTransposes = kRecordTransposes<W, N, S>;
  for (std::size_t t = 0; t < kTransposes; ++t) {
    V block[W];
    transpose_rows<V>(rows, t * W, block);
    for (std::size_t k = 0; k < W && t * W + k < N; ++k) out[t * W + k] = block[k];
  }
  for (std::size_t k = kTransposes * W; k < N; ++k) out[k] = V([&](auto lane) { return rows[lane][k]; });
}

/// The inverse of load_record_values for the first N values (N <= W) of
/// each record: rows[l][k] = x[k] lane l for k < N, for every lane whose
/// `write` is set. A float record is written with one masked row store where
/// the ISA has them (AVX-512, AVX2), after transposing the N vectors back into
/// rows; elsewhere lane by lane. Lanes not written are not touched at all.
template <class V, std::size_t N, std::size_t S, class Index>
COLLIDE_LANE_INLINE void store_record_values(typename V::value_type* records, const Index* idx, const V* x,
                                             const typename V::mask_type& write) {
  constexpr std::size_t W = V::size();
  using T = typename V::value_type;
  static_assert(N <= S);
#if defined(__AVX512F__)
  if constexpr (std::is_same_v<T, float> && W == 16 && N <= 16) {
    __m512 r[16];
    for (std::size_t k = 0; k < 16; ++k) r[k] = k < N ? static_cast<__m512>(x[k]) : _mm512_setzero_ps();
    __m512 o[16];
    transpose_float_registers<16>(r, o);
    constexpr __mmask16 kFields = static_cast<__mmask16>((1u << N) - 1);
    for (std::size_t l = 0; l < 16; ++l) {
      if (write[l]) _mm512_mask_storeu_ps(records + static_cast<std::size_t>(idx[l]) * S, kFields, o[l]);
    }
    return;
  }
#endif
#if defined(__AVX2__)
  if constexpr (std::is_same_v<T, float> && W == 8 && N <= 8) {
    __m256 r[8];
    for (std::size_t k = 0; k < 8; ++k) r[k] = k < N ? static_cast<__m256>(x[k]) : _mm256_setzero_ps();
    __m256 o[8];
    transpose_float_registers<8>(r, o);
    const __m256i fields =
        _mm256_cmpgt_epi32(_mm256_set1_epi32(static_cast<int>(N)), _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
    for (std::size_t l = 0; l < 8; ++l) {
      if (write[l]) _mm256_maskstore_ps(records + static_cast<std::size_t>(idx[l]) * S, fields, o[l]);
    }
    return;
  }
#endif
  for (std::size_t l = 0; l < W; ++l) {
    if (!write[l]) continue;
    T* row = records + static_cast<std::size_t>(idx[l]) * S;
    for (std::size_t k = 0; k < N; ++k) row[k] = x[k][l];
  }
}

}  // namespace COLLIDE_KERNEL_NS
}  // namespace collide::detail
