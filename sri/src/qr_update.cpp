#include "gvins/sri/qr_update.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

namespace gvins::sri {

namespace {

/// Householder reflector H = I − τ v vᵀ, v = [1; x̃], with H [α; x] = [β; 0] (the convention of
/// LAPACK's xLARFG), for a contiguous x[0..n). On return alpha = β and x = x̃. The norm is
/// scaled when the squares could under- or overflow.
template <typename Scalar>
Scalar makeReflectorRaw(Scalar& alpha, Scalar* x, int n) {
  Scalar ss = 0;
  for (int i = 0; i < n; ++i) ss += x[i] * x[i];
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

/// Givens rotation [c s; −s c] with −s·a + c·b = 0 and c·a + s·b = ρ = hypot(a, b) ≥ 0 for
/// b ≠ 0 (Golub & Van Loan, Algorithm 5.1.3, scaled against overflow).
template <typename Scalar>
inline Scalar makeGivens(Scalar a, Scalar b, Scalar& c, Scalar& s) {
  if (b == Scalar(0)) {  // identity (ρ = a keeps its sign; the sign of a row of R is free)
    c = Scalar(1);
    s = Scalar(0);
    return a;
  }
  const Scalar aa = std::abs(a);
  const Scalar ab = std::abs(b);
  Scalar rho;
  if (ab > aa) {
    const Scalar t = a / b;
    rho = ab * std::sqrt(Scalar(1) + t * t);
  } else {
    const Scalar t = b / a;
    rho = aa * std::sqrt(Scalar(1) + t * t);
  }
  c = a / rho;
  s = b / rho;
  return rho;
}

#if defined(__GNUC__) || defined(__clang__)
#define GVINS_SRI_VECTOR_EXT 1
#if defined(__AVX__)
#define GVINS_SRI_SIMD_BYTES 32
#else
#define GVINS_SRI_SIMD_BYTES 16
#endif
/// SIMD vector of Scalar (GCC/Clang vector extension): 16 bytes (SSE2, the x86-64 baseline) or
/// 32 bytes when the target has AVX (-march=native, GVINS_SRI_NATIVE).
template <typename Scalar>
struct Simd {
  typedef Scalar type __attribute__((vector_size(GVINS_SRI_SIMD_BYTES)));
  static constexpr int kLanes = GVINS_SRI_SIMD_BYTES / static_cast<int>(sizeof(Scalar));
  static type load(const Scalar* p) {
    type v;
    std::memcpy(&v, p, sizeof(v));
    return v;
  }
  static void store(Scalar* p, type v) { std::memcpy(p, &v, sizeof(v)); }
  static type broadcast(Scalar s) { return type{} + s; }
};
#endif

/// Qᵀ = I − V Tᵀ Vᵀ of P reflectors (V = [I_P; V_W]) applied to the columns [t0, len) of the P
/// pivot rows x[p] of R and of the a rows of W (row i at w0 + i·ws): Z = X + V_Wᵀ W,
/// Z ← Tᵀ Z, X −= Z, W −= V_W Z. V_W(i, p) = v[p·a + i] (column-major); T is P×P upper
/// triangular, column-major.
template <typename Scalar, int P>
void applyReflectorsScalar(Scalar* const* x, Scalar* w0, std::ptrdiff_t ws, int a, int t0, int len,
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

#ifdef GVINS_SRI_VECTOR_EXT
/// One chunk of NV SIMD vectors (columns t0 .. t0 + NV·lanes) of applyReflectors.
template <typename Scalar, int P, int NV>
inline void applyReflectorsChunk(Scalar* const* x, Scalar* w0, std::ptrdiff_t ws, int a, int t0,
                                 const typename Simd<Scalar>::type* vv, const Scalar* T) {
  using V = Simd<Scalar>;
  using Vec = typename V::type;
  constexpr int L = V::kLanes;
  Vec z[P][NV];
  for (int p = 0; p < P; ++p) {
    for (int u = 0; u < NV; ++u) z[p][u] = V::load(x[p] + t0 + u * L);
  }
  for (int i = 0; i < a; ++i) {
    const Scalar* wi = w0 + i * ws + t0;
    Vec wr[NV];
    for (int u = 0; u < NV; ++u) wr[u] = V::load(wi + u * L);
    for (int p = 0; p < P; ++p) {
      const Vec vp = vv[i * P + p];
      for (int u = 0; u < NV; ++u) z[p][u] += vp * wr[u];
    }
  }
  for (int p = P - 1; p >= 0; --p) {  // Z ← Tᵀ Z (Tᵀ lower triangular)
    const Vec tpp = V::broadcast(T[p * P + p]);
    Vec acc[NV];
    for (int u = 0; u < NV; ++u) acc[u] = tpp * z[p][u];
    for (int q = 0; q < p; ++q) {
      const Vec tq = V::broadcast(T[p * P + q]);
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
      const Vec vp = vv[i * P + p];
      for (int u = 0; u < NV; ++u) wr[u] -= vp * z[p][u];
    }
    for (int u = 0; u < NV; ++u) V::store(wi + u * L, wr[u]);
  }
}
#endif

/// As applyReflectorsScalar on [0, len), register-blocked: per chunk of 2 SIMD vectors the P
/// rows of Z stay in registers while the rows of W stream through twice. vb holds V_W(i, p)
/// broadcast to full vectors at vb[i·P + p] (SSE2 has no cheap broadcast from memory).
template <typename Scalar, int P>
void applyReflectors(Scalar* const* x, Scalar* w0, std::ptrdiff_t ws, int a, int len,
                     const Scalar* v, [[maybe_unused]] const void* vb, const Scalar* T) {
  int t0 = 0;
#ifdef GVINS_SRI_VECTOR_EXT
  using V = Simd<Scalar>;
  constexpr int L = V::kLanes;
  const auto* vv = static_cast<const typename V::type*>(vb);
  for (; t0 + 2 * L <= len; t0 += 2 * L) applyReflectorsChunk<Scalar, P, 2>(x, w0, ws, a, t0, vv, T);
  for (; t0 + L <= len; t0 += L) applyReflectorsChunk<Scalar, P, 1>(x, w0, ws, a, t0, vv, T);
#endif
  applyReflectorsScalar<Scalar, P>(x, w0, ws, a, t0, len, v, T);
}

/// Columns (reflectors) per panel of the Householder update. Four reflectors × two SIMD vectors
/// fill 8 of the 16 SSE registers with the panel's Z; measured faster at n = 150…400 than wider
/// panels whose trailing update goes through Eigen's matrix products (docs/sri_core.md).
constexpr int kFusedPanel = 4;

}  // namespace

template <typename Scalar>
void householderRowUpdate(RowMatrixView<Scalar> R, VectorView<Scalar> r, RowMatrixView<Scalar> W,
                          VectorView<Scalar> z, std::span<const int> lead) {
  const int k = static_cast<int>(R.rows());
  const int m = static_cast<int>(W.rows());
  if (m == 0 || k == 0 || lead.empty() || lead[0] >= k) return;
  const std::ptrdiff_t ws = W.outerStride();
  // Narrow panels: the panel's columns of W are copied to a contiguous column-major block,
  // its reflectors broadcast to SIMD vectors for the register-blocked kernel.
  std::vector<Scalar> vc(static_cast<std::size_t>(kFusedPanel * m));
#ifdef GVINS_SRI_VECTOR_EXT
  std::vector<typename Simd<Scalar>::type> vb(static_cast<std::size_t>(kFusedPanel * m));
  void* vbp = vb.data();
#else
  void* vbp = nullptr;
#endif
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
        const Scalar t = makeReflectorRaw<Scalar>(R(j, j), v, a);
        tauv[jj] = t;
        if (t == Scalar(0)) continue;
        for (int c = jj + 1; c < jb; ++c) {
          Scalar* vcol = V + c * a;
          Scalar dot = R(j, j0 + c);
          for (int i = 0; i < a; ++i) dot += v[i] * vcol[i];
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
          Scalar d = 0;
          for (int i = 0; i < a; ++i) d += V[p * a + i] * V[q * a + i];
          g[p] = -tauv[q] * d;
        }
        for (int p = 0; p < q; ++p) {
          Scalar acc = 0;
          for (int l = p; l < q; ++l) acc += Tc[l * jb + p] * g[l];
          Tc[q * jb + p] = acc;
        }
      }
#ifdef GVINS_SRI_VECTOR_EXT
      auto* vbv = static_cast<typename Simd<Scalar>::type*>(vbp);
      for (int i = 0; i < a; ++i) {
        for (int p = 0; p < jb; ++p) vbv[i * jb + p] = Simd<Scalar>::broadcast(V[p * a + i]);
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
          applyReflectors<Scalar, 4>(x, w0, ws, a, nt, V, vbp, Tc);
          applyReflectorsScalar<Scalar, 4>(xr, z.data(), 1, a, 0, 1, V, Tc);
          break;
        case 3:
          applyReflectors<Scalar, 3>(x, w0, ws, a, nt, V, vbp, Tc);
          applyReflectorsScalar<Scalar, 3>(xr, z.data(), 1, a, 0, 1, V, Tc);
          break;
        case 2:
          applyReflectors<Scalar, 2>(x, w0, ws, a, nt, V, vbp, Tc);
          applyReflectorsScalar<Scalar, 2>(xr, z.data(), 1, a, 0, 1, V, Tc);
          break;
        default:
          applyReflectors<Scalar, 1>(x, w0, ws, a, nt, V, vbp, Tc);
          applyReflectorsScalar<Scalar, 1>(xr, z.data(), 1, a, 0, 1, V, Tc);
          break;
      }
      j0 += jb;
    }
  }
}

namespace {

template <typename Scalar, int P>
void chainRotationsScalar(Scalar* const* x, Scalar* w0, std::ptrdiff_t ws, int a, int t0, int len,
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
template <typename Scalar, int P, int NV>
inline void chainRotationsChunk(Scalar* const* x, Scalar* w0, std::ptrdiff_t ws, int a, int t0,
                                const typename Simd<Scalar>::type* cb,
                                const typename Simd<Scalar>::type* sb) {
  using V = Simd<Scalar>;
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
      const Vec c = cb[i * P + p];
      const Vec sn = sb[i * P + p];
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
template <typename Scalar, int P>
void chainRotations(Scalar* const* x, Scalar* w0, std::ptrdiff_t ws, int a, int len,
                    const Scalar* C, const Scalar* S, int ld, [[maybe_unused]] const void* cb,
                    [[maybe_unused]] const void* sb) {
  int t0 = 0;
#ifdef GVINS_SRI_VECTOR_EXT
  using V = Simd<Scalar>;
  using Vec = typename V::type;
  constexpr int L = V::kLanes;
  const auto* cv = static_cast<const Vec*>(cb);
  const auto* sv = static_cast<const Vec*>(sb);
  for (; t0 + 2 * L <= len; t0 += 2 * L) chainRotationsChunk<Scalar, P, 2>(x, w0, ws, a, t0, cv, sv);
  for (; t0 + L <= len; t0 += L) chainRotationsChunk<Scalar, P, 1>(x, w0, ws, a, t0, cv, sv);
#endif
  chainRotationsScalar<Scalar, P>(x, w0, ws, a, t0, len, C, S, ld);
}

/// Columns handled per pass by the Givens update.
constexpr int kGivensPanel = 4;

}  // namespace

template <typename Scalar>
void givensRowUpdate(RowMatrixView<Scalar> R, VectorView<Scalar> r, RowMatrixView<Scalar> W,
                     VectorView<Scalar> z, std::span<const int> lead) {
  constexpr int P = kGivensPanel;
  const int k = static_cast<int>(R.rows());
  const int m = static_cast<int>(W.rows());
  if (m == 0 || k == 0 || lead.empty() || lead[0] >= k) return;
  // Rotation (c, s) of panel column p with row i of W at C[p·m + i], S[p·m + i] (and broadcast
  // at cb[i·P + p], sb[i·P + p]); the panel's columns of W are copied to the column-major vc.
  std::vector<Scalar> C(static_cast<std::size_t>(P * m));
  std::vector<Scalar> S(static_cast<std::size_t>(P * m));
  std::vector<Scalar> vc(static_cast<std::size_t>(P * m));
#ifdef GVINS_SRI_VECTOR_EXT
  using Vec = typename Simd<Scalar>::type;
  std::vector<Vec> cbv(static_cast<std::size_t>(P * m));
  std::vector<Vec> sbv(static_cast<std::size_t>(P * m));
#endif
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
          cbv[static_cast<std::size_t>(i * pw + q)] = Simd<Scalar>::broadcast(C[q * m + i]);
          sbv[static_cast<std::size_t>(i * pw + q)] = Simd<Scalar>::broadcast(S[q * m + i]);
        }
      }
      const void* cb = cbv.data();
      const void* sb = sbv.data();
#else
      const void* cb = nullptr;
      const void* sb = nullptr;
#endif
      switch (pw) {
        case 4: chainRotations<Scalar, 4>(x, w0, ws, a, len, C.data(), S.data(), m, cb, sb); break;
        case 3: chainRotations<Scalar, 3>(x, w0, ws, a, len, C.data(), S.data(), m, cb, sb); break;
        case 2: chainRotations<Scalar, 2>(x, w0, ws, a, len, C.data(), S.data(), m, cb, sb); break;
        default: chainRotations<Scalar, 1>(x, w0, ws, a, len, C.data(), S.data(), m, cb, sb); break;
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

template <typename Scalar>
void sweepColumnsToFront(RowMatrixView<Scalar> R, VectorView<Scalar> r, int c, int d, int t) {
  const int n = static_cast<int>(R.cols());
  if (d <= 0 || c <= t) return;
  std::vector<Scalar> cs(static_cast<std::size_t>(d));
  std::vector<Scalar> sn(static_cast<std::size_t>(d));
#ifdef GVINS_SRI_VECTOR_EXT
  std::vector<typename Simd<Scalar>::type> cb(static_cast<std::size_t>(d));
  std::vector<typename Simd<Scalar>::type> sb(static_cast<std::size_t>(d));
#endif
  const int cend = c + d;
  for (int i = c - 1; i >= t; --i) {
    // Rotation k acts on rows (i+k, i+k+1) and zeroes R(i+k+1, c+k); computed sequentially on
    // the moved block's columns, where the previous rotations have to be applied first.
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
      cs[static_cast<std::size_t>(k)] = ck;
      sn[static_cast<std::size_t>(k)] = sk;
#ifdef GVINS_SRI_VECTOR_EXT
      cb[static_cast<std::size_t>(k)] = Simd<Scalar>::broadcast(ck);
      sb[static_cast<std::size_t>(k)] = Simd<Scalar>::broadcast(sk);
#endif
    }
    // The same chain on the other columns ≥ i and on r: one pass per row, the "bottom" result
    // of rotation k is carried into rotation k+1.
    // One pass per chunk of columns with the carried row in registers: each row of the window
    // is loaded and stored once.
    auto chain = [&](int col0, int len) {
      if (len <= 0) return;
      int q0 = 0;
#ifdef GVINS_SRI_VECTOR_EXT
      using V = Simd<Scalar>;
      using Vec = typename V::type;
      constexpr int L = V::kLanes;
      Scalar* base = &R(i, col0);
      const std::ptrdiff_t rs = R.outerStride();
      for (; q0 + 2 * L <= len; q0 += 2 * L) {
        Vec c0 = V::load(base + q0);
        Vec c1 = V::load(base + q0 + L);
        for (int k = 0; k < d; ++k) {
          const Vec ck = cb[static_cast<std::size_t>(k)];
          const Vec sk = sb[static_cast<std::size_t>(k)];
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
      for (int q = q0; q < len; ++q) {
        Scalar x = R(i, col0 + q);
        for (int k = 0; k < d; ++k) {
          const Scalar y = R(i + k + 1, col0 + q);
          R(i + k, col0 + q) = cs[static_cast<std::size_t>(k)] * x + sn[static_cast<std::size_t>(k)] * y;
          x = cs[static_cast<std::size_t>(k)] * y - sn[static_cast<std::size_t>(k)] * x;
        }
        R(i + d, col0 + q) = x;
      }
    };
    // Column i: only row i is non-zero there (the rows below are below their diagonals, whose
    // storage is not read), so the chain reduces to scalars.
    {
      Scalar x = R(i, i);
      for (int k = 0; k < d; ++k) {
        R(i + k, i) = cs[static_cast<std::size_t>(k)] * x;
        x = -sn[static_cast<std::size_t>(k)] * x;
      }
      R(i + d, i) = x;
    }
    chain(i + 1, c - i - 1);
    chain(cend, n - cend);
    Scalar x = r(i);
    for (int k = 0; k < d; ++k) {
      const Scalar y = r(i + k + 1);
      r(i + k) = cs[static_cast<std::size_t>(k)] * x + sn[static_cast<std::size_t>(k)] * y;
      x = cs[static_cast<std::size_t>(k)] * y - sn[static_cast<std::size_t>(k)] * x;
    }
    r(i + d) = x;
  }
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
