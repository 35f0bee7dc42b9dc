#include "gvins/sri/qr_update.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <type_traits>
#include <utility>
#include <vector>

namespace gvins::sri {

namespace {

#if defined(__GNUC__) || defined(__clang__)
#define GVINS_SRI_VECTOR_EXT 1
// 32-byte vectors only pass between always-inlined functions (never through a call), so the
// ABI note GCC gives for them in non-AVX translation units does not apply.
#pragma GCC diagnostic ignored "-Wpsabi"
#define GVINS_SRI_INLINE inline __attribute__((always_inline))
#define GVINS_SRI_LAMBDA_INLINE __attribute__((always_inline))
/// SIMD vector of Scalar (GCC/Clang vector extension) of B bytes: 16 (SSE2, the x86-64
/// baseline) or 32 (AVX2). The kernels below are templates on B and always inlined into the
/// per-instruction-set entry points at the end of the file, so that AVX code only exists inside
/// functions compiled with __attribute__((target("avx2"))) and is only run when the CPU has it
/// (runtime dispatch; no shared inline function is ever compiled for AVX).
template <typename Scalar, int B>
struct Simd;
#define GVINS_SRI_SIMD(BYTES)                                                          \
  template <typename Scalar>                                                           \
  struct Simd<Scalar, BYTES> {                                                         \
    typedef Scalar type __attribute__((vector_size(BYTES)));                           \
    static constexpr int kLanes = BYTES / static_cast<int>(sizeof(Scalar));            \
    GVINS_SRI_INLINE static type load(const Scalar* p) {                               \
      type v;                                                                          \
      std::memcpy(&v, p, sizeof(v));                                                   \
      return v;                                                                        \
    }                                                                                  \
    GVINS_SRI_INLINE static void store(Scalar* p, type v) { std::memcpy(p, &v, sizeof(v)); } \
  };
GVINS_SRI_SIMD(16)
GVINS_SRI_SIMD(32)
#undef GVINS_SRI_SIMD
/// Vector of *p in every lane, as a shuffle of lane 0: in AVX2 code a scalar load and one
/// register vbroadcastss/sd (GCC 12 builds {s, s, …} or `type{} + s` from a loaded float with a
/// chain of vinsertps, and `type{} + s` keeps an add, since 0 + (−0) is +0).
template <typename Scalar, int B, int... I>
GVINS_SRI_INLINE typename Simd<Scalar, B>::type loadBroadcastImpl(const Scalar* p, std::integer_sequence<int, I...>) {
  typename Simd<Scalar, B>::type v{};
  v[0] = *p;
  return __builtin_shufflevector(v, v, ((void)I, 0)...);
}
template <typename Scalar, int B>
GVINS_SRI_INLINE typename Simd<Scalar, B>::type loadBroadcast(const Scalar* p) {
  return loadBroadcastImpl<Scalar, B>(p, std::make_integer_sequence<int, Simd<Scalar, B>::kLanes>{});
}
#else
#define GVINS_SRI_INLINE inline
#define GVINS_SRI_LAMBDA_INLINE
#endif

/// Broadcast table: value k at b[k·L .. k·L + L) (L lanes of B bytes), loaded with one
/// (unaligned) vector load; plain Scalar storage so that no vector type leaves the kernels.
template <typename Scalar, int B>
GVINS_SRI_INLINE void putBroadcast(Scalar* b, int k, Scalar v) {
  constexpr int L = B / static_cast<int>(sizeof(Scalar));
  for (int l = 0; l < L; ++l) b[k * L + l] = v;
}

/// Σ a[i]·b[i] over n entries with SIMD partial sums (four vectors): the plain loop is one
/// dependent scalar add per entry (the compiler may not reassociate it), which made the
/// reflector norms and panel dot products of householderImpl latency-bound.
template <typename Scalar, int B>
GVINS_SRI_INLINE Scalar dotSimd(const Scalar* a, const Scalar* b, int n) {
  int i = 0;
  Scalar s = 0;
#ifdef GVINS_SRI_VECTOR_EXT
  using V = Simd<Scalar, B>;
  using Vec = typename V::type;
  constexpr int L = V::kLanes;
  if (n >= 4 * L) {
    Vec s0{};
    Vec s1 = s0;
    Vec s2 = s0;
    Vec s3 = s0;
    for (; i + 4 * L <= n; i += 4 * L) {
      s0 += V::load(a + i) * V::load(b + i);
      s1 += V::load(a + i + L) * V::load(b + i + L);
      s2 += V::load(a + i + 2 * L) * V::load(b + i + 2 * L);
      s3 += V::load(a + i + 3 * L) * V::load(b + i + 3 * L);
    }
    s0 = (s0 + s1) + (s2 + s3);
    for (int l = 0; l < L; ++l) s += s0[l];
  }
#endif
  for (; i < n; ++i) s += a[i] * b[i];
  return s;
}

/// Householder reflector H = I − τ v vᵀ, v = [1; x̃], with H [α; x] = [β; 0] (the convention of
/// LAPACK's xLARFG), for a contiguous x[0..n). On return alpha = β and x = x̃. The norm is
/// scaled when the squares could under- or overflow.
template <typename Scalar, int B>
GVINS_SRI_INLINE Scalar makeReflectorRaw(Scalar& alpha, Scalar* x, int n) {
  const Scalar ss = dotSimd<Scalar, B>(x, x, n);
  if (ss == Scalar(0)) return Scalar(0);
  Scalar norm;
  // Unscaled unless the squares may have lost precision to underflow or overflowed.
  constexpr Scalar kSmall = std::numeric_limits<Scalar>::min() / std::numeric_limits<Scalar>::epsilon();
  constexpr Scalar kBig = std::numeric_limits<Scalar>::max() / Scalar(4);
  if (ss > kSmall && ss < kBig && alpha * alpha < kBig) {
    norm = std::sqrt(alpha * alpha + ss);
  } else {
    Scalar xmax = std::abs(alpha);
    for (int i = 0; i < n; ++i) xmax = std::max(xmax, std::abs(x[i]));
    const Scalar inv = Scalar(1) / xmax;
    Scalar sc = (alpha * inv) * (alpha * inv);
    for (int i = 0; i < n; ++i) sc += (x[i] * inv) * (x[i] * inv);
    norm = xmax * std::sqrt(sc);
  }
  const Scalar beta = alpha >= Scalar(0) ? -norm : norm;
  const Scalar tau = (beta - alpha) / beta;
  const Scalar scale = Scalar(1) / (alpha - beta);
  for (int i = 0; i < n; ++i) x[i] *= scale;
  alpha = beta;
  return tau;
}

/// Qᵀ = I − V Tᵀ Vᵀ of P reflectors (V = [I_P; V_W]) applied to the columns [t0, len) of the P
/// pivot rows x[p] of R and of the a rows of W (row i at w0 + i·ws): Z = X + V_Wᵀ W,
/// Z ← Tᵀ Z, X −= Z, W −= V_W Z. V_W(i, p) = v[p·a + i] (column-major); T is P×P upper
/// triangular, column-major.
template <typename Scalar, int P>
GVINS_SRI_INLINE void applyReflectorsScalar(Scalar* const* x, Scalar* w0, std::ptrdiff_t ws, int a, int t0, int len,
                           const Scalar* v, const Scalar* T) {
  for (; t0 < len; ++t0) {
    Scalar zr[P];
    for (int p = 0; p < P; ++p) zr[p] = x[p][t0];
    for (int i = 0; i < a; ++i) {
      const Scalar wv = w0[i * ws + t0];
      for (int p = 0; p < P; ++p) zr[p] += v[p * a + i] * wv;
    }
    for (int p = P - 1; p >= 0; --p) {
      Scalar acc = T[p * P + p] * zr[p];
      for (int q = 0; q < p; ++q) acc += T[p * P + q] * zr[q];
      zr[p] = acc;
    }
    for (int p = 0; p < P; ++p) x[p][t0] -= zr[p];
    for (int i = 0; i < a; ++i) {
      Scalar acc = 0;
      for (int p = 0; p < P; ++p) acc += v[p * a + i] * zr[p];
      w0[i * ws + t0] -= acc;
    }
  }
}

/// applyReflectorsScalar for a few trailing columns (fewer than two SIMD vectors, or the
/// right-hand side): rows outer, so that the P·(len − t0) sums are independent instead of P
/// chains of a dependent additions each (the column-outer loop was latency-bound).
template <typename Scalar, int P>
GVINS_SRI_INLINE void applyReflectorsTail(Scalar* const* x, Scalar* w0, std::ptrdiff_t ws, int a, int t0, int len,
                                          const Scalar* v, const Scalar* T) {
  constexpr int kMax = 16;
  const int nc = len - t0;
  if (nc <= 0) return;
  if (nc > kMax) return applyReflectorsScalar<Scalar, P>(x, w0, ws, a, t0, len, v, T);
  Scalar zr[P][kMax];
  for (int p = 0; p < P; ++p) {
    for (int c = 0; c < nc; ++c) zr[p][c] = x[p][t0 + c];
  }
  for (int i = 0; i < a; ++i) {
    const Scalar* wi = w0 + i * ws + t0;
    for (int p = 0; p < P; ++p) {
      const Scalar vp = v[p * a + i];
      for (int c = 0; c < nc; ++c) zr[p][c] += vp * wi[c];
    }
  }
  for (int c = 0; c < nc; ++c) {
    for (int p = P - 1; p >= 0; --p) {
      Scalar acc = T[p * P + p] * zr[p][c];
      for (int q = 0; q < p; ++q) acc += T[p * P + q] * zr[q][c];
      zr[p][c] = acc;
    }
  }
  for (int p = 0; p < P; ++p) {
    for (int c = 0; c < nc; ++c) x[p][t0 + c] -= zr[p][c];
  }
  for (int i = 0; i < a; ++i) {
    Scalar* wi = w0 + i * ws + t0;
    for (int c = 0; c < nc; ++c) {
      Scalar acc = 0;
      for (int p = 0; p < P; ++p) acc += v[p * a + i] * zr[p][c];
      wi[c] -= acc;
    }
  }
}

#ifdef GVINS_SRI_VECTOR_EXT
/// One chunk of NV SIMD vectors (columns t0 .. t0 + NV·lanes) of applyReflectors.
template <typename Scalar, int B, int P, int NV>
GVINS_SRI_INLINE void applyReflectorsChunk(Scalar* const* x, Scalar* w0, std::ptrdiff_t ws, int a,
                                           int t0, const Scalar* v, const Scalar* vv, const Scalar* T) {
  using V = Simd<Scalar, B>;
  using Vec = typename V::type;
  constexpr int L = V::kLanes;
  // V_W(i, p) as a full vector: AVX2 broadcasts it from v (a load and a register broadcast);
  // SSE2 has no broadcast instruction and reads the pre-broadcast table vv.
  auto vcoef = [&](int i, int p) GVINS_SRI_LAMBDA_INLINE {
    if constexpr (B >= 32) {
      return loadBroadcast<Scalar, B>(v + p * a + i);
    } else {
      return V::load(vv + (i * P + p) * L);
    }
  };
  Vec z[P][NV];
  for (int p = 0; p < P; ++p) {
    for (int u = 0; u < NV; ++u) z[p][u] = V::load(x[p] + t0 + u * L);
  }
  for (int i = 0; i < a; ++i) {
    const Scalar* wi = w0 + i * ws + t0;
    Vec wr[NV];
    for (int u = 0; u < NV; ++u) wr[u] = V::load(wi + u * L);
    for (int p = 0; p < P; ++p) {
      const Vec vp = vcoef(i, p);
      for (int u = 0; u < NV; ++u) z[p][u] += vp * wr[u];
    }
  }
  for (int p = P - 1; p >= 0; --p) {  // Z ← Tᵀ Z (Tᵀ lower triangular)
    const Vec tpp = loadBroadcast<Scalar, B>(T + p * P + p);
    Vec acc[NV];
    for (int u = 0; u < NV; ++u) acc[u] = tpp * z[p][u];
    for (int q = 0; q < p; ++q) {
      const Vec tq = loadBroadcast<Scalar, B>(T + p * P + q);
      for (int u = 0; u < NV; ++u) acc[u] += tq * z[q][u];
    }
    for (int u = 0; u < NV; ++u) z[p][u] = acc[u];
  }
  for (int p = 0; p < P; ++p) {
    for (int u = 0; u < NV; ++u) V::store(x[p] + t0 + u * L, V::load(x[p] + t0 + u * L) - z[p][u]);
  }
  for (int i = 0; i < a; ++i) {
    Scalar* wi = w0 + i * ws + t0;
    Vec wr[NV];
    for (int u = 0; u < NV; ++u) wr[u] = V::load(wi + u * L);
    for (int p = 0; p < P; ++p) {
      const Vec vp = vcoef(i, p);
      for (int u = 0; u < NV; ++u) wr[u] -= vp * z[p][u];
    }
    for (int u = 0; u < NV; ++u) V::store(wi + u * L, wr[u]);
  }
}
#endif

/// As applyReflectorsScalar on [0, len), register-blocked: per chunk of 3 (AVX2) or 2 (SSE2)
/// SIMD vectors the P rows of Z stay in registers while the rows of W stream through twice.
/// vv holds V_W(i, p) broadcast to full vectors at vv[i·P + p] for SSE2, which has no broadcast
/// load (AVX2 broadcasts from v: the table of 4·a·lanes entries no longer crowds W out of L1).
template <typename Scalar, int B, int P>
GVINS_SRI_INLINE void applyReflectors(Scalar* const* x, Scalar* w0, std::ptrdiff_t ws, int a, int len,
                                      const Scalar* v, [[maybe_unused]] const Scalar* vv,
                                      const Scalar* T) {
  int t0 = 0;
#ifdef GVINS_SRI_VECTOR_EXT
  constexpr int L = Simd<Scalar, B>::kLanes;
  // A remainder of r < L columns as one more SIMD vector over the last L columns [len − L, len),
  // which overlaps L − r columns of the main loop: its inputs are saved before the main loop and the
  // chunk is computed on the copy, so the overlapped columns get the same values twice (columns
  // are independent, the per-lane operations are the same). The scalar tail cost as much as the
  // vectors on ~100-column trailing blocks with float's 8 lanes (docs/sri_core.md).
  const bool overlap = len % L != 0 && len >= L;
  const int tl = len - L;  // first column of the overlapping vector
  static thread_local std::vector<Scalar> saved;
  if (overlap) {
    const std::size_t need = static_cast<std::size_t>((a + P) * L);
    if (saved.size() < need) saved.resize(need);
    for (int p = 0; p < P; ++p) std::memcpy(saved.data() + p * L, x[p] + tl, sizeof(Scalar) * L);
    for (int i = 0; i < a; ++i) std::memcpy(saved.data() + (P + i) * L, w0 + i * ws + tl, sizeof(Scalar) * L);
  }
  if constexpr (B >= 32) {  // 16 vector registers: 12 sums of Z, 3 rows of W, 1 coefficient
    for (; t0 + 3 * L <= len; t0 += 3 * L) applyReflectorsChunk<Scalar, B, P, 3>(x, w0, ws, a, t0, v, vv, T);
  }
  for (; t0 + 2 * L <= len; t0 += 2 * L) applyReflectorsChunk<Scalar, B, P, 2>(x, w0, ws, a, t0, v, vv, T);
  for (; t0 + L <= len; t0 += L) applyReflectorsChunk<Scalar, B, P, 1>(x, w0, ws, a, t0, v, vv, T);
  if (overlap) {
    Scalar* sx[P];
    for (int p = 0; p < P; ++p) sx[p] = saved.data() + p * L;
    applyReflectorsChunk<Scalar, B, P, 1>(sx, saved.data() + P * L, L, a, 0, v, vv, T);
    // Whole vectors back (one load and store each; the overlapped columns get their own values).
    for (int p = 0; p < P; ++p) std::memcpy(x[p] + tl, saved.data() + p * L, sizeof(Scalar) * L);
    for (int i = 0; i < a; ++i) std::memcpy(w0 + i * ws + tl, saved.data() + (P + i) * L, sizeof(Scalar) * L);
    return;
  }
#endif
  applyReflectorsTail<Scalar, P>(x, w0, ws, a, t0, len, v, T);
}

/// Columns (reflectors) per panel of the Householder update. Four reflectors × two (SSE2) or
/// three (AVX2) SIMD vectors hold the panel's Z in registers; measured faster at n = 150…400 than wider
/// panels whose trailing update goes through Eigen's matrix products (docs/sri_core.md).
constexpr int kFusedPanel = 4;

}  // namespace

template <typename Scalar, int B>
GVINS_SRI_INLINE void householderImpl(RowMatrixView<Scalar> R, VectorView<Scalar> r, RowMatrixView<Scalar> W,
                                      VectorView<Scalar> z, std::span<const int> lead) {
  const int k = static_cast<int>(R.rows());
  const int m = static_cast<int>(W.rows());
  if (m == 0 || k == 0 || lead.empty() || lead[0] >= k) return;
  const std::ptrdiff_t ws = W.outerStride();
  // Narrow panels: the panel's columns of W are copied to a contiguous column-major block,
  // its reflectors broadcast to SIMD vectors for the register-blocked kernel.
  constexpr int L = B / static_cast<int>(sizeof(Scalar));
  // Per-thread panel buffers, grown on demand and not cleared: every entry that is read was
  // written first (rows < a of the panel). Saves an allocation and its zero fill per update.
  static thread_local std::vector<Scalar> vc;
  static thread_local std::vector<Scalar> vb;
  if (vc.size() < static_cast<std::size_t>(kFusedPanel * m)) vc.resize(static_cast<std::size_t>(kFusedPanel * m));
  if (B < 32 && vb.size() < static_cast<std::size_t>(kFusedPanel * m * L)) vb.resize(static_cast<std::size_t>(kFusedPanel * m * L));
  Scalar* vbp = vb.data();
  int a = 0;  // active rows: lead < end of the panel
  for (int j0 = lead[0]; j0 < k;) {
    {
      const int jb = std::min(kFusedPanel, k - j0);
      while (a < m && lead[static_cast<std::size_t>(a)] < j0 + jb) ++a;
      Scalar* V = vc.data();
      for (int i = 0; i < a; ++i) {
        const Scalar* wi = &W(i, j0);
        for (int p = 0; p < jb; ++p) V[p * a + i] = wi[p];
      }
      Scalar tauv[kFusedPanel];
      for (int jj = 0; jj < jb; ++jj) {
        const int j = j0 + jj;
        Scalar* v = V + jj * a;
        const Scalar t = makeReflectorRaw<Scalar, B>(R(j, j), v, a);
        tauv[jj] = t;
        if (t == Scalar(0)) continue;
        for (int c = jj + 1; c < jb; ++c) {
          Scalar* vcol = V + c * a;
          Scalar dot = R(j, j0 + c) + dotSimd<Scalar, B>(v, vcol, a);
          dot *= t;
          R(j, j0 + c) -= dot;
          for (int i = 0; i < a; ++i) vcol[i] -= dot * v[i];
        }
      }
      // T (column-major jb×jb): T_{1:q−1,q} = −τ_q T_{1:q−1,1:q−1} V_Wᵀ v_q.
      Scalar Tc[kFusedPanel * kFusedPanel] = {};
      for (int q = 0; q < jb; ++q) {
        Tc[q * jb + q] = tauv[q];
        if (tauv[q] == Scalar(0)) continue;
        Scalar g[kFusedPanel];
        for (int p = 0; p < q; ++p) {
          const Scalar d = dotSimd<Scalar, B>(V + p * a, V + q * a, a);
          g[p] = -tauv[q] * d;
        }
        for (int p = 0; p < q; ++p) {
          Scalar acc = 0;
          for (int l = p; l < q; ++l) acc += Tc[l * jb + p] * g[l];
          Tc[q * jb + p] = acc;
        }
      }
#ifdef GVINS_SRI_VECTOR_EXT
      if constexpr (B < 32) {
        for (int i = 0; i < a; ++i) {
          for (int p = 0; p < jb; ++p) putBroadcast<Scalar, B>(vbp, i * jb + p, V[p * a + i]);
        }
      }
#endif
      const int c1 = j0 + jb;
      const int nt = k - c1;
      Scalar* x[kFusedPanel];
      Scalar* xr[kFusedPanel];
      for (int p = 0; p < jb; ++p) {
        x[p] = &R(j0 + p, 0) + c1;
        xr[p] = r.data() + j0 + p;
      }
      Scalar* w0 = &W(0, 0) + c1;
      switch (jb) {
        case 4:
          applyReflectors<Scalar, B, 4>(x, w0, ws, a, nt, V, vbp, Tc);
          applyReflectorsTail<Scalar, 4>(xr, z.data(), 1, a, 0, 1, V, Tc);
          break;
        case 3:
          applyReflectors<Scalar, B, 3>(x, w0, ws, a, nt, V, vbp, Tc);
          applyReflectorsTail<Scalar, 3>(xr, z.data(), 1, a, 0, 1, V, Tc);
          break;
        case 2:
          applyReflectors<Scalar, B, 2>(x, w0, ws, a, nt, V, vbp, Tc);
          applyReflectorsTail<Scalar, 2>(xr, z.data(), 1, a, 0, 1, V, Tc);
          break;
        default:
          applyReflectors<Scalar, B, 1>(x, w0, ws, a, nt, V, vbp, Tc);
          applyReflectorsTail<Scalar, 1>(xr, z.data(), 1, a, 0, 1, V, Tc);
          break;
      }
      j0 += jb;
    }
  }
}

namespace {

template <typename Scalar, int P>
GVINS_SRI_INLINE void chainRotationsScalar(Scalar* const* x, Scalar* w0, std::ptrdiff_t ws, int a, int t0, int len,
                          const Scalar* C, const Scalar* S, int ld) {
  for (; t0 < len; ++t0) {
    Scalar xr[P];
    for (int p = 0; p < P; ++p) xr[p] = x[p][t0];
    for (int i = 0; i < a; ++i) {
      Scalar wv = w0[i * ws + t0];
      for (int p = 0; p < P; ++p) {
        const Scalar c = C[p * ld + i];
        const Scalar sn = S[p * ld + i];
        const Scalar xv = xr[p];
        xr[p] = c * xv + sn * wv;
        wv = c * wv - sn * xv;
      }
      w0[i * ws + t0] = wv;
    }
    for (int p = 0; p < P; ++p) x[p][t0] = xr[p];
  }
}

#ifdef GVINS_SRI_VECTOR_EXT
/// One chunk of NV SIMD vectors of chainRotations.
template <typename Scalar, int B, int P, int NV>
GVINS_SRI_INLINE void chainRotationsChunk(Scalar* const* x, Scalar* w0, std::ptrdiff_t ws, int a,
                                          int t0, const Scalar* cb, const Scalar* sb) {
  using V = Simd<Scalar, B>;
  using Vec = typename V::type;
  constexpr int L = V::kLanes;
  Vec xr[P][NV];
  for (int p = 0; p < P; ++p) {
    for (int u = 0; u < NV; ++u) xr[p][u] = V::load(x[p] + t0 + u * L);
  }
  for (int i = 0; i < a; ++i) {
    Scalar* wi = w0 + i * ws + t0;
    Vec wr[NV];
    for (int u = 0; u < NV; ++u) wr[u] = V::load(wi + u * L);
    for (int p = 0; p < P; ++p) {
      const Vec c = V::load(cb + (i * P + p) * L);
      const Vec sn = V::load(sb + (i * P + p) * L);
      for (int u = 0; u < NV; ++u) {
        const Vec xv = xr[p][u];
        xr[p][u] = c * xv + sn * wr[u];
        wr[u] = c * wr[u] - sn * xv;
      }
    }
    for (int u = 0; u < NV; ++u) V::store(wi + u * L, wr[u]);
  }
  for (int p = 0; p < P; ++p) {
    for (int u = 0; u < NV; ++u) V::store(x[p] + t0 + u * L, xr[p][u]);
  }
}
#endif

/// Applies, on the columns [0, len) of P pivot rows x[p] and of the a rows of W (row stride
/// ws), the rotations of P consecutive columns: for every row i of W and p = 0..P−1 in turn,
/// (x_p, w_i) ← (c x_p + s w_i, c w_i − s x_p) with (c, s) = (C[p·ld + i], S[p·ld + i]).
/// This order is a valid reordering of "all rotations of column p, then of column p+1": two
/// rotations that do not share a row commute. The pivot rows of a chunk of 2 SIMD vectors stay
/// in registers while the rows of W stream through once (register blocking). cb, sb hold the
/// same c, s broadcast to SIMD vectors at [i·P + p].
template <typename Scalar, int B, int P>
GVINS_SRI_INLINE void chainRotations(Scalar* const* x, Scalar* w0, std::ptrdiff_t ws, int a, int len,
                                     const Scalar* C, const Scalar* S, int ld,
                                     [[maybe_unused]] const Scalar* cb, [[maybe_unused]] const Scalar* sb) {
  int t0 = 0;
#ifdef GVINS_SRI_VECTOR_EXT
  constexpr int L = Simd<Scalar, B>::kLanes;
  for (; t0 + 2 * L <= len; t0 += 2 * L) chainRotationsChunk<Scalar, B, P, 2>(x, w0, ws, a, t0, cb, sb);
  for (; t0 + L <= len; t0 += L) chainRotationsChunk<Scalar, B, P, 1>(x, w0, ws, a, t0, cb, sb);
#endif
  chainRotationsScalar<Scalar, P>(x, w0, ws, a, t0, len, C, S, ld);
}

/// Columns handled per pass by the Givens update.
constexpr int kGivensPanel = 4;

}  // namespace

template <typename Scalar, int B>
GVINS_SRI_INLINE void givensImpl(RowMatrixView<Scalar> R, VectorView<Scalar> r, RowMatrixView<Scalar> W,
                                 VectorView<Scalar> z, std::span<const int> lead) {
  constexpr int P = kGivensPanel;
  constexpr int L = B / static_cast<int>(sizeof(Scalar));
  const int k = static_cast<int>(R.rows());
  const int m = static_cast<int>(W.rows());
  if (m == 0 || k == 0 || lead.empty() || lead[0] >= k) return;
  // Rotation (c, s) of panel column p with row i of W at C[p·m + i], S[p·m + i] (and broadcast
  // at cb[i·P + p], sb[i·P + p]); the panel's columns of W are copied to the column-major vc.
  std::vector<Scalar> C(static_cast<std::size_t>(P * m));
  std::vector<Scalar> S(static_cast<std::size_t>(P * m));
  std::vector<Scalar> vc(static_cast<std::size_t>(P * m));
  std::vector<Scalar> cbv(static_cast<std::size_t>(P * m * L));
  std::vector<Scalar> sbv(static_cast<std::size_t>(P * m * L));
  const std::ptrdiff_t ws = W.outerStride();
  int a = 0;
  for (int j0 = lead[0]; j0 < k; j0 += P) {
    const int pw = std::min(P, k - j0);
    while (a < m && lead[static_cast<std::size_t>(a)] < j0 + pw) ++a;
    const int pend = j0 + pw;
    Scalar* V = vc.data();
    for (int i = 0; i < a; ++i) {
      const Scalar* wi = &W(i, 0) + j0;
      for (int q = 0; q < pw; ++q) V[q * a + i] = wi[q];
    }
    // Panel: the rotations of each column, applied at once to the rest of the panel.
    for (int q = 0; q < pw; ++q) {
      Scalar* cq = C.data() + static_cast<std::ptrdiff_t>(q) * m;
      Scalar* sq = S.data() + static_cast<std::ptrdiff_t>(q) * m;
      const int j = j0 + q;
      Scalar piv = R(j, j);
      Scalar* rj = &R(j, 0);
      const Scalar* vq = V + q * a;
      for (int i = 0; i < a; ++i) {
        const Scalar wv = vq[i];
        if (wv == Scalar(0)) {
          cq[i] = Scalar(1);
          sq[i] = Scalar(0);
          continue;
        }
        Scalar c;
        Scalar sn;
        piv = makeGivens(piv, wv, c, sn);
        cq[i] = c;
        sq[i] = sn;
        for (int col = q + 1; col < pw; ++col) {
          const Scalar xv = rj[j0 + col];
          const Scalar yv = V[col * a + i];
          rj[j0 + col] = c * xv + sn * yv;
          V[col * a + i] = c * yv - sn * xv;
        }
      }
      R(j, j) = piv;
    }
    // Trailing columns, all panel rotations in one pass.
    const int len = k - pend;
    if (len > 0) {
      Scalar* x[P];
      for (int q = 0; q < pw; ++q) x[q] = &R(j0 + q, 0) + pend;
      Scalar* w0 = &W(0, 0) + pend;
#ifdef GVINS_SRI_VECTOR_EXT
      for (int i = 0; i < a; ++i) {
        for (int q = 0; q < pw; ++q) {
          putBroadcast<Scalar, B>(cbv.data(), i * pw + q, C[q * m + i]);
          putBroadcast<Scalar, B>(sbv.data(), i * pw + q, S[q * m + i]);
        }
      }
#endif
      const Scalar* cb = cbv.data();
      const Scalar* sb = sbv.data();
      switch (pw) {
        case 4: chainRotations<Scalar, B, 4>(x, w0, ws, a, len, C.data(), S.data(), m, cb, sb); break;
        case 3: chainRotations<Scalar, B, 3>(x, w0, ws, a, len, C.data(), S.data(), m, cb, sb); break;
        case 2: chainRotations<Scalar, B, 2>(x, w0, ws, a, len, C.data(), S.data(), m, cb, sb); break;
        default: chainRotations<Scalar, B, 1>(x, w0, ws, a, len, C.data(), S.data(), m, cb, sb); break;
      }
    }
    // Right-hand side.
    for (int q = 0; q < pw; ++q) {
      const Scalar* cq = C.data() + static_cast<std::ptrdiff_t>(q) * m;
      const Scalar* sq = S.data() + static_cast<std::ptrdiff_t>(q) * m;
      Scalar rv = r(j0 + q);
      for (int i = 0; i < a; ++i) {
        const Scalar zi = z(i);
        z(i) = cq[i] * zi - sq[i] * rv;
        rv = cq[i] * rv + sq[i] * zi;
      }
      r(j0 + q) = rv;
    }
  }
}

/// Two consecutive steps of the sweep fused on NV SIMD vectors of columns (base: row i of the
/// first step): step A (row i, rotations ca/sa) and step B (row i − 1, rotations cb/sb), where
/// B's rotation k needs A's new row i + k. Per column the order of the rotations is that of the
/// two steps one after the other; each row is loaded and stored once for both steps.
template <typename Scalar, int B, int NV>
GVINS_SRI_INLINE void sweepPairChunk(Scalar* base, std::ptrdiff_t rs, int d, const Scalar* ca, const Scalar* sa,
                                     const Scalar* cb, const Scalar* sb) {
#ifdef GVINS_SRI_VECTOR_EXT
  using V = Simd<Scalar, B>;
  using Vec = typename V::type;
  constexpr int L = V::kLanes;
  Vec xa[NV];
  Vec xb[NV];
  for (int u = 0; u < NV; ++u) {
    xa[u] = V::load(base + u * L);
    xb[u] = V::load(base - rs + u * L);
  }
  for (int k = 0; k < d; ++k) {
    const Vec cak = V::load(ca + k * L);
    const Vec sak = V::load(sa + k * L);
    const Vec cbk = V::load(cb + k * L);
    const Vec sbk = V::load(sb + k * L);
    const Scalar* bot = base + (k + 1) * rs;
    Scalar* topb = base + (k - 1) * rs;
    for (int u = 0; u < NV; ++u) {
      const Vec y = V::load(bot + u * L);
      const Vec ta = cak * xa[u] + sak * y;  // step A's new row i + k
      xa[u] = cak * y - sak * xa[u];
      V::store(topb + u * L, cbk * xb[u] + sbk * ta);
      xb[u] = cbk * ta - sbk * xb[u];
    }
  }
  for (int u = 0; u < NV; ++u) {
    V::store(base + (d - 1) * rs + u * L, xb[u]);
    V::store(base + d * rs + u * L, xa[u]);
  }
#endif
}

template <typename Scalar, int B>
GVINS_SRI_INLINE void sweepImpl(RowMatrixView<Scalar> R, VectorView<Scalar> r, int c, int d, int t) {
  const int n = static_cast<int>(R.cols());
  if (d <= 0 || c <= t) return;
  constexpr int LB = B / static_cast<int>(sizeof(Scalar));
  // Rotations of up to two steps: step h (0: row i, 1: row i − 1) at [h·d + k].
  std::vector<Scalar> cs(static_cast<std::size_t>(2 * d));
  std::vector<Scalar> sn(static_cast<std::size_t>(2 * d));
  std::vector<Scalar> cb(static_cast<std::size_t>(2 * d * LB));
  std::vector<Scalar> sb(static_cast<std::size_t>(2 * d * LB));
  const int cend = c + d;
  const std::ptrdiff_t rs = R.outerStride();
  // Step of row i: rotation k acts on rows (i+k, i+k+1) and zeroes R(i+k+1, c+k); computed
  // sequentially on the moved block's columns, where the previous rotations have to be applied
  // first. The next step (row i − 1) only needs this one's result on these columns.
  auto coefficients = [&](int i, int h) GVINS_SRI_LAMBDA_INLINE {
    for (int k = 0; k < d; ++k) {
      const int top = i + k;
      const int bot = top + 1;
      Scalar ck;
      Scalar sk;
      R(top, c + k) = makeGivens(R(top, c + k), R(bot, c + k), ck, sk);
      R(bot, c + k) = Scalar(0);
      for (int q = k + 1; q < d; ++q) {
        const Scalar x = R(top, c + q);
        const Scalar y = R(bot, c + q);
        R(top, c + q) = ck * x + sk * y;
        R(bot, c + q) = ck * y - sk * x;
      }
      cs[static_cast<std::size_t>(h * d + k)] = ck;
      sn[static_cast<std::size_t>(h * d + k)] = sk;
      putBroadcast<Scalar, B>(cb.data() + h * d * LB, k, ck);
      putBroadcast<Scalar, B>(sb.data() + h * d * LB, k, sk);
    }
  };
  // The step's chain on one column (or on r): the "bottom" result of rotation k is carried into
  // rotation k+1.
  auto chainScalar = [&](Scalar* col, std::ptrdiff_t stride, int h) GVINS_SRI_LAMBDA_INLINE {
    const Scalar* ch = cs.data() + h * d;
    const Scalar* sh = sn.data() + h * d;
    Scalar x = col[0];
    for (int k = 0; k < d; ++k) {
      const Scalar y = col[(k + 1) * stride];
      col[k * stride] = ch[k] * x + sh[k] * y;
      x = ch[k] * y - sh[k] * x;
    }
    col[d * stride] = x;
  };
  // Column i of row i's step: only row i is non-zero there (the rows below are below their
  // diagonals, whose storage is not read), so the chain reduces to scalars.
  auto firstColumn = [&](int i, int h) GVINS_SRI_LAMBDA_INLINE {
    Scalar x = R(i, i);
    for (int k = 0; k < d; ++k) {
      R(i + k, i) = cs[static_cast<std::size_t>(h * d + k)] * x;
      x = -sn[static_cast<std::size_t>(h * d + k)] * x;
    }
    R(i + d, i) = x;
  };
  // One step on the columns [col0, col0 + len): one pass per chunk of columns with the carried
  // row in registers, each row of the window loaded and stored once.
  auto chain = [&](int i, int col0, int len) GVINS_SRI_LAMBDA_INLINE {
    if (len <= 0) return;
    int q0 = 0;
#ifdef GVINS_SRI_VECTOR_EXT
    using V = Simd<Scalar, B>;
    using Vec = typename V::type;
    constexpr int L = V::kLanes;
    Scalar* base = &R(i, col0);
    for (; q0 + 2 * L <= len; q0 += 2 * L) {
      Vec c0 = V::load(base + q0);
      Vec c1 = V::load(base + q0 + L);
      for (int k = 0; k < d; ++k) {
        const Vec ck = V::load(cb.data() + k * L);
        const Vec sk = V::load(sb.data() + k * L);
        Scalar* top = base + k * rs + q0;
        const Scalar* bot = top + rs;
        const Vec y0 = V::load(bot);
        const Vec y1 = V::load(bot + L);
        V::store(top, ck * c0 + sk * y0);
        V::store(top + L, ck * c1 + sk * y1);
        c0 = ck * y0 - sk * c0;
        c1 = ck * y1 - sk * c1;
      }
      V::store(base + d * rs + q0, c0);
      V::store(base + d * rs + q0 + L, c1);
    }
#endif
    for (int q = q0; q < len; ++q) chainScalar(&R(i, col0 + q), rs, 0);
  };
  // Steps of rows i and i − 1 fused on the columns [col0, col0 + len) (both act there).
  auto pairChain = [&](int i, int col0, int len) GVINS_SRI_LAMBDA_INLINE {
    if (len <= 0) return;
    int q0 = 0;
#ifdef GVINS_SRI_VECTOR_EXT
    constexpr int L = Simd<Scalar, B>::kLanes;
    Scalar* base = &R(i, col0);
    const Scalar* ca = cb.data();
    const Scalar* sa = sb.data();
    const Scalar* cbb = cb.data() + d * LB;
    const Scalar* sbb = sb.data() + d * LB;
    for (; q0 + 2 * L <= len; q0 += 2 * L) sweepPairChunk<Scalar, B, 2>(base + q0, rs, d, ca, sa, cbb, sbb);
    for (; q0 + L <= len; q0 += L) sweepPairChunk<Scalar, B, 1>(base + q0, rs, d, ca, sa, cbb, sbb);
#endif
    for (int q = q0; q < len; ++q) {
      chainScalar(&R(i, col0 + q), rs, 0);
      chainScalar(&R(i - 1, col0 + q), rs, 1);
    }
  };
  int i = c - 1;
  for (; i - 1 >= t; i -= 2) {  // pairs of steps: rows i, then i − 1
    coefficients(i, 0);
    coefficients(i - 1, 1);
    firstColumn(i, 0);
    chainScalar(&R(i - 1, i), rs, 1);  // column i: an ordinary column of step i − 1
    firstColumn(i - 1, 1);
    pairChain(i, i + 1, c - i - 1);
    pairChain(i, cend, n - cend);
    chainScalar(r.data() + i, 1, 0);
    chainScalar(r.data() + i - 1, 1, 1);
  }
  if (i >= t) {  // a last single step
    coefficients(i, 0);
    firstColumn(i, 0);
    chain(i, i + 1, c - i - 1);
    chain(i, cend, n - cend);
    chainScalar(r.data() + i, 1, 0);
  }
}

// ---------------------------------------------------------------- instruction-set dispatch
// The kernels are built twice: for the x86-64 baseline (SSE2, 16-byte vectors) and, in functions
// with __attribute__((target("avx2,fma"))), for AVX2 (32-byte vectors) with fused multiply-adds
// (this file is compiled with -ffp-contract=fast, sri/CMakeLists.txt: a·b + c becomes one FMA
// in the AVX2 functions; the baseline has no FMA instruction, so nothing changes there). The
// AVX2 path is taken when the CPU (and OS) support AVX2 and FMA; GVINS_SRI_SIMD=sse2 in the
// environment forces the baseline (for benchmarks and tests). Same algorithm; the FMAs and the
// SIMD partial sums (more lanes with AVX2) round differently: results agree to rounding.
namespace {
#if defined(GVINS_SRI_VECTOR_EXT) && (defined(__x86_64__) || defined(__i386__)) && !defined(__AVX2__)
#define GVINS_SRI_DISPATCH 1
bool useAvx2() {
  static const bool yes = [] {
    const char* e = std::getenv("GVINS_SRI_SIMD");
    if (e && std::strcmp(e, "sse2") == 0) return false;
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") != 0 && __builtin_cpu_supports("fma") != 0;
  }();
  return yes;
}
#define GVINS_SRI_AVX2_ENTRY(NAME, IMPL, SCALAR, PARAMS, ARGS) \
  __attribute__((target("avx2,fma"))) void NAME PARAMS { IMPL<SCALAR, 32> ARGS; }
#define GVINS_SRI_ENTRIES(S)                                                                    \
  GVINS_SRI_AVX2_ENTRY(householderAvx2_##S, householderImpl, S,                                 \
                       (RowMatrixView<S> R, VectorView<S> r, RowMatrixView<S> W, VectorView<S> z, \
                        std::span<const int> lead),                                             \
                       (R, r, W, z, lead))                                                      \
  GVINS_SRI_AVX2_ENTRY(givensAvx2_##S, givensImpl, S,                                           \
                       (RowMatrixView<S> R, VectorView<S> r, RowMatrixView<S> W, VectorView<S> z, \
                        std::span<const int> lead),                                             \
                       (R, r, W, z, lead))                                                      \
  GVINS_SRI_AVX2_ENTRY(sweepAvx2_##S, sweepImpl, S,                                             \
                       (RowMatrixView<S> R, VectorView<S> r, int c, int d, int t), (R, r, c, d, t))
GVINS_SRI_ENTRIES(float)
GVINS_SRI_ENTRIES(double)
#undef GVINS_SRI_ENTRIES
#undef GVINS_SRI_AVX2_ENTRY
template <typename S> struct Avx2;
template <> struct Avx2<float> {
  static constexpr auto householder = &householderAvx2_float;
  static constexpr auto givens = &givensAvx2_float;
  static constexpr auto sweep = &sweepAvx2_float;
};
template <> struct Avx2<double> {
  static constexpr auto householder = &householderAvx2_double;
  static constexpr auto givens = &givensAvx2_double;
  static constexpr auto sweep = &sweepAvx2_double;
};
#endif
#if defined(__AVX2__)
constexpr int kBaseBytes = 32;
#else
constexpr int kBaseBytes = 16;
#endif
}  // namespace

template <typename Scalar>
void householderRowUpdate(RowMatrixView<Scalar> R, VectorView<Scalar> r, RowMatrixView<Scalar> W,
                          VectorView<Scalar> z, std::span<const int> lead) {
#ifdef GVINS_SRI_DISPATCH
  if (useAvx2()) return Avx2<Scalar>::householder(R, r, W, z, lead);
#endif
  householderImpl<Scalar, kBaseBytes>(R, r, W, z, lead);
}

template <typename Scalar>
void givensRowUpdate(RowMatrixView<Scalar> R, VectorView<Scalar> r, RowMatrixView<Scalar> W,
                     VectorView<Scalar> z, std::span<const int> lead) {
#ifdef GVINS_SRI_DISPATCH
  if (useAvx2()) return Avx2<Scalar>::givens(R, r, W, z, lead);
#endif
  givensImpl<Scalar, kBaseBytes>(R, r, W, z, lead);
}

template <typename Scalar>
void sweepColumnsToFront(RowMatrixView<Scalar> R, VectorView<Scalar> r, int c, int d, int t) {
#ifdef GVINS_SRI_DISPATCH
  if (useAvx2()) return Avx2<Scalar>::sweep(R, r, c, d, t);
#endif
  sweepImpl<Scalar, kBaseBytes>(R, r, c, d, t);
}

#define GVINS_SRI_INSTANTIATE(S)                                                              \
  template void householderRowUpdate<S>(RowMatrixView<S>, VectorView<S>, RowMatrixView<S>,    \
                                        VectorView<S>, std::span<const int>);                 \
  template void givensRowUpdate<S>(RowMatrixView<S>, VectorView<S>, RowMatrixView<S>,         \
                                   VectorView<S>, std::span<const int>);                      \
  template void sweepColumnsToFront<S>(RowMatrixView<S>, VectorView<S>, int, int, int);
GVINS_SRI_INSTANTIATE(float)
GVINS_SRI_INSTANTIATE(double)
#undef GVINS_SRI_INSTANTIATE

}  // namespace gvins::sri
