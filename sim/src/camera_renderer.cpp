#include "gvins/sim/camera_renderer.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
#include <immintrin.h>
#endif

#include "gvins/sim/random.hpp"

namespace gvins::sim {
namespace {

/// Inverse standard normal CDF at 4096 equally likely cells, for fast per-pixel noise (a
/// 12-bit index per variate). Built once by bisection on erfc.
struct NormalTable {
  std::array<float, 4096> v{};
  NormalTable() {
    for (int k = 0; k < 4096; ++k) {
      const double p = (k + 0.5) / 4096.0;
      double lo = -10.0, hi = 10.0;
      for (int i = 0; i < 80; ++i) {
        const double mid = 0.5 * (lo + hi);
        (0.5 * std::erfc(-mid / std::sqrt(2.0)) < p ? lo : hi) = mid;
      }
      v[static_cast<std::size_t>(k)] = static_cast<float>(0.5 * (lo + hi));
    }
    // Normalise to unit variance exactly (the cell midpoints slightly under-disperse).
    double s2 = 0.0;
    for (float x : v) s2 += static_cast<double>(x) * x;
    const double scale = 1.0 / std::sqrt(s2 / 4096.0);
    for (float& x : v) x = static_cast<float>(x * scale);
  }
};
const NormalTable& normalTable() {
  static const NormalTable t;
  return t;
}

/// One mip level's tiles over a rectangle, for lock-free lookups while rendering a frame.
/// Texel coordinates relative to the view: fx = gx * inv + offX with gx the ground x relative
/// to the frame origin; texel i of the view is tile (i >> 7), column (i & 127).
struct LevelView {
  int level = 0;
  float inv = 1.0f;          // 1 / texel size
  float offX = 0, offY = 0;  // frame origin to view texel coordinates (minus the half texel)
  int nx = 0, ny = 0;        // tiles
  std::vector<std::shared_ptr<const GroundTexture::Tile>> tiles;
  std::vector<const float*> data;
};

constexpr int kTile = GroundTexture::kTileSize;
constexpr int kTileShift = 7;
static_assert((1 << kTileShift) == kTile);
constexpr std::size_t kStride = kTile + 1;

inline std::int64_t floorDivTile(std::int64_t i) { return i >= 0 ? i / kTile : -((-i + kTile - 1) / kTile); }

/// log2 to ~1e-3 for positive normal floats (exponent plus a cubic in the mantissa).
inline float fastLog2(float x) {
  std::uint32_t b;
  std::memcpy(&b, &x, 4);
  const auto e = static_cast<float>(static_cast<int>((b >> 23) & 255) - 127);
  b = (b & 0x007FFFFFu) | 0x3F800000u;
  float m;
  std::memcpy(&m, &b, 4);  // [1, 2)
  // Minimax-like cubic for log2(m) on [1, 2).
  return e + ((0.15824871f * m - 1.05187502f) * m + 3.04788415f) * m - 2.15541759f;
}

/// Bilinear sample; `fallback` is called for points outside the view.
template <class Fallback>
inline float sampleView(const LevelView& v, float gx, float gy, Fallback&& fallback) {
  const float fx = gx * v.inv + v.offX, fy = gy * v.inv + v.offY;
  if (!(fx >= 0.0f && fy >= 0.0f)) return fallback(v.level);
  const auto i = static_cast<int>(fx), j = static_cast<int>(fy);
  const int tx = i >> kTileShift, ty = j >> kTileShift;
  if (tx >= v.nx || ty >= v.ny) return fallback(v.level);
  const float* p = v.data[static_cast<std::size_t>(ty * v.nx + tx)] +
                   static_cast<std::size_t>(j & (kTile - 1)) * kStride + static_cast<std::size_t>(i & (kTile - 1));
  const float wx = fx - static_cast<float>(i), wy = fy - static_cast<float>(j);
  return (1.0f - wy) * ((1.0f - wx) * p[0] + wx * p[1]) + wy * ((1.0f - wx) * p[kStride] + wx * p[kStride + 1]);
}

/// What the AVX2 row kernel needs of one row and of the frame's level views.
struct RowKernel {
  float r00, r01, r02, r10, r11, r12, r20, r21, r22;
  float cx, cy, cz, maxRange, l2s0, maxL, weight;
  int maxLevel;
  const float* base;  // texel index origin of the views' int32 tile offsets
  const float* inv;   // per level
  const float* offX;
  const float* offY;
  const int* nx;
  const int* ny;
  const std::int32_t* const* tileOff;  // per level: tile start in texels from `base`, or null
};

#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
#define GVINS_SIM_HAVE_AVX2_KERNEL 1
bool cpuHasAvx2() {
  static const bool has = __builtin_cpu_supports("avx2");
  return has;
}

/// Bilinear samples of 8 lanes of one level view; false if a lane is outside it.
__attribute__((target("avx2"))) inline bool sampleView8(const RowKernel& k, int l, __m256 gx, __m256 gy, __m256& val) {
  const std::int32_t* off = k.tileOff[l];
  if (!off) return false;
  const __m256 fx = _mm256_add_ps(_mm256_mul_ps(gx, _mm256_set1_ps(k.inv[l])), _mm256_set1_ps(k.offX[l]));
  const __m256 fy = _mm256_add_ps(_mm256_mul_ps(gy, _mm256_set1_ps(k.inv[l])), _mm256_set1_ps(k.offY[l]));
  const __m256 zero = _mm256_setzero_ps();
  const __m256 nonneg = _mm256_and_ps(_mm256_cmp_ps(fx, zero, _CMP_GE_OQ), _mm256_cmp_ps(fy, zero, _CMP_GE_OQ));
  if (_mm256_movemask_ps(nonneg) != 0xFF) return false;
  const __m256i i = _mm256_cvttps_epi32(fx), j = _mm256_cvttps_epi32(fy);
  const __m256i tx = _mm256_srai_epi32(i, kTileShift), ty = _mm256_srai_epi32(j, kTileShift);
  // 0 <= tx < nx and 0 <= ty < ny (a conversion overflow gives INT_MIN, caught by >= 0).
  const __m256i minus1 = _mm256_set1_epi32(-1);
  const __m256i in = _mm256_and_si256(
      _mm256_and_si256(_mm256_cmpgt_epi32(tx, minus1), _mm256_cmpgt_epi32(_mm256_set1_epi32(k.nx[l]), tx)),
      _mm256_and_si256(_mm256_cmpgt_epi32(ty, minus1), _mm256_cmpgt_epi32(_mm256_set1_epi32(k.ny[l]), ty)));
  if (_mm256_movemask_ps(_mm256_castsi256_ps(in)) != 0xFF) return false;
  const __m256i tile = _mm256_add_epi32(_mm256_mullo_epi32(ty, _mm256_set1_epi32(k.nx[l])), tx);
  const __m256i mask = _mm256_set1_epi32(kTile - 1);
  const __m256i idx = _mm256_add_epi32(
      _mm256_i32gather_epi32(off, tile, 4),
      _mm256_add_epi32(_mm256_mullo_epi32(_mm256_and_si256(j, mask), _mm256_set1_epi32(static_cast<int>(kStride))),
                       _mm256_and_si256(i, mask)));
  const __m256 p0 = _mm256_i32gather_ps(k.base, idx, 4);
  const __m256 p1 = _mm256_i32gather_ps(k.base, _mm256_add_epi32(idx, _mm256_set1_epi32(1)), 4);
  const __m256 p2 = _mm256_i32gather_ps(k.base, _mm256_add_epi32(idx, _mm256_set1_epi32(static_cast<int>(kStride))), 4);
  const __m256 p3 = _mm256_i32gather_ps(k.base, _mm256_add_epi32(idx, _mm256_set1_epi32(static_cast<int>(kStride) + 1)), 4);
  const __m256 wx = _mm256_sub_ps(fx, _mm256_cvtepi32_ps(i)), wy = _mm256_sub_ps(fy, _mm256_cvtepi32_ps(j));
  const __m256 one = _mm256_set1_ps(1.0f);
  const __m256 ax = _mm256_sub_ps(one, wx), ay = _mm256_sub_ps(one, wy);
  // Same operations in the same order as sampleView (no FMA: the results are bit-identical).
  const __m256 top = _mm256_add_ps(_mm256_mul_ps(ax, p0), _mm256_mul_ps(wx, p1));
  const __m256 bot = _mm256_add_ps(_mm256_mul_ps(ax, p2), _mm256_mul_ps(wx, p3));
  val = _mm256_add_ps(_mm256_mul_ps(ay, top), _mm256_mul_ps(wy, bot));
  return true;
}

/// The per-pixel loop of CameraRenderer::accumulate for pixels [0, 8 floor(w / 8)) of a row,
/// 8 at a time, with the scalar loop's operations in its order (so bit-identical pixels).
/// Blocks it cannot do (a ray off the ground or beyond the range, lanes at different mip
/// levels, a lane outside a level view) are listed in `failed` (first pixel) for the scalar
/// loop; returns their number.
__attribute__((target("avx2"))) int accumulateRowAvx2(const RowKernel& k, const float* rx, const float* ry,
                                                      const float* rnorm, const float* pangle, float* out, int w,
                                                      int* failed) {
  int nFailed = 0;
  const __m256 r00 = _mm256_set1_ps(k.r00), r01 = _mm256_set1_ps(k.r01), r02 = _mm256_set1_ps(k.r02);
  const __m256 r10 = _mm256_set1_ps(k.r10), r11 = _mm256_set1_ps(k.r11), r12 = _mm256_set1_ps(k.r12);
  const __m256 r20 = _mm256_set1_ps(k.r20), r21 = _mm256_set1_ps(k.r21), r22 = _mm256_set1_ps(k.r22);
  const __m256 cx = _mm256_set1_ps(k.cx), cy = _mm256_set1_ps(k.cy), negCz = _mm256_set1_ps(-k.cz);
  const __m256 maxRange = _mm256_set1_ps(k.maxRange), l2s0 = _mm256_set1_ps(k.l2s0);
  const __m256 maxL = _mm256_set1_ps(k.maxL), weight = _mm256_set1_ps(k.weight);
  const __m256 zero = _mm256_setzero_ps(), one = _mm256_set1_ps(1.0f);
  const __m256 signMask = _mm256_set1_ps(-0.0f);
  for (int u = 0; u + 8 <= w; u += 8) {
    if (!(k.cz > 0.0f)) {
      failed[nFailed++] = u;
      continue;
    }
    const __m256 x = _mm256_loadu_ps(rx + u), y = _mm256_loadu_ps(ry + u);
    const __m256 dz = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(r20, x), _mm256_mul_ps(r21, y)), r22);
    const __m256 lam = _mm256_div_ps(negCz, dz);
    const __m256 rn = _mm256_loadu_ps(rnorm + u);
    const __m256 dist = _mm256_mul_ps(lam, rn);
    const __m256 ok = _mm256_and_ps(_mm256_cmp_ps(dz, _mm256_set1_ps(-1e-6f), _CMP_LT_OQ),
                                    _mm256_cmp_ps(dist, maxRange, _CMP_LE_OQ));
    if (_mm256_movemask_ps(ok) != 0xFF) {
      failed[nFailed++] = u;
      continue;
    }
    const __m256 gx = _mm256_add_ps(
        cx, _mm256_mul_ps(lam, _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(r00, x), _mm256_mul_ps(r01, y)), r02)));
    const __m256 gy = _mm256_add_ps(
        cy, _mm256_mul_ps(lam, _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(r10, x), _mm256_mul_ps(r11, y)), r12)));
    const __m256 cosInc = _mm256_div_ps(_mm256_xor_ps(dz, signMask), rn);
    const __m256 arg = _mm256_div_ps(_mm256_mul_ps(dist, _mm256_loadu_ps(pangle + u)), _mm256_sqrt_ps(cosInc));
    // fastLog2
    const __m256i b = _mm256_castps_si256(arg);
    const __m256 e = _mm256_cvtepi32_ps(
        _mm256_sub_epi32(_mm256_and_si256(_mm256_srli_epi32(b, 23), _mm256_set1_epi32(255)), _mm256_set1_epi32(127)));
    const __m256 m = _mm256_castsi256_ps(_mm256_or_si256(_mm256_and_si256(b, _mm256_set1_epi32(0x007FFFFF)),
                                                         _mm256_set1_epi32(0x3F800000)));
    __m256 poly = _mm256_sub_ps(_mm256_mul_ps(_mm256_set1_ps(0.15824871f), m), _mm256_set1_ps(1.05187502f));
    poly = _mm256_add_ps(_mm256_mul_ps(poly, m), _mm256_set1_ps(3.04788415f));
    poly = _mm256_mul_ps(poly, m);
    __m256 level = _mm256_sub_ps(_mm256_sub_ps(_mm256_add_ps(e, poly), _mm256_set1_ps(2.15541759f)), l2s0);
    // std::clamp(level, 0, maxL): level < 0 -> 0, maxL < level -> maxL (level is never NaN here).
    level = _mm256_blendv_ps(level, zero, _mm256_cmp_ps(level, zero, _CMP_LT_OQ));
    level = _mm256_blendv_ps(level, maxL, _mm256_cmp_ps(maxL, level, _CMP_LT_OQ));
    const __m256i l0v = _mm256_cvttps_epi32(level);
    const int l0 = _mm256_cvtsi256_si32(l0v);
    if (_mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(l0v, _mm256_set1_epi32(l0)))) != 0xFF) {
      failed[nFailed++] = u;
      continue;
    }
    const __m256 f = _mm256_sub_ps(level, _mm256_cvtepi32_ps(l0v));
    __m256 val;
    if (!sampleView8(k, l0, gx, gy, val)) {
      failed[nFailed++] = u;
      continue;
    }
    if (l0 < k.maxLevel) {
      const __m256 second = _mm256_cmp_ps(f, _mm256_set1_ps(1e-3f), _CMP_GT_OQ);
      if (_mm256_movemask_ps(second) != 0) {
        __m256 val1;
        if (!sampleView8(k, l0 + 1, gx, gy, val1)) {
          failed[nFailed++] = u;
          continue;
        }
        const __m256 mixed = _mm256_add_ps(_mm256_mul_ps(_mm256_sub_ps(one, f), val), _mm256_mul_ps(f, val1));
        val = _mm256_blendv_ps(val, mixed, second);
      }
    }
    _mm256_storeu_ps(out + u, _mm256_add_ps(_mm256_loadu_ps(out + u), _mm256_mul_ps(weight, val)));
  }
  return nFailed;
}
#endif

/// The per-pixel ray tables of a camera (CameraRenderer's).
struct PixelRays {
  const float* x;      // undistorted normalised coordinates
  const float* y;
  const float* norm;   // |(x, y, 1)|
  const float* angle;  // sqrt(solid angle), rad
  int w, h;
};

/// Pixel spacing of the grid on which a frame's texture tiles are planned.
constexpr int kPlanStep = 16;

/// Ground extent read at one mip level (empty while x0 > x1).
struct GroundBox {
  double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
};

/// The ground extent each mip level of a frame is read over, from the pixels of a coarse grid
/// (every kPlanStep pixels and the last row and column); `poseOf(v)` is the camera pose of row v
/// (rotation R, position p in the local frame).
template <class PoseOf>
std::vector<GroundBox> groundExtents(const PoseOf& poseOf, const PixelRays& rays, double maxRange, double log2s0,
                                     int maxLevel) {
  std::vector<GroundBox> boxes(static_cast<std::size_t>(maxLevel + 1));
  auto groundAt = [&](int u, int v, double& gx, double& gy, double& level) {
    const auto& P = poseOf(v);
    const std::size_t i = static_cast<std::size_t>(v) * rays.w + u;
    const Eigen::Vector3d d = P.R * Eigen::Vector3d(rays.x[i], rays.y[i], 1.0);
    if (d.z() >= -1e-6 || P.p.z() <= 0.0) return false;
    const double lam = -P.p.z() / d.z();
    const double dist = lam * rays.norm[i];
    if (dist > maxRange) return false;
    gx = P.p.x() + lam * d.x();
    gy = P.p.y() + lam * d.y();
    const double cosInc = -d.z() / rays.norm[i];
    level = std::log2(dist * rays.angle[i] / std::sqrt(cosInc)) - log2s0;
    return true;
  };
  for (int v = 0;; v = std::min(v + kPlanStep, rays.h - 1)) {
    for (int u = 0;; u = std::min(u + kPlanStep, rays.w - 1)) {
      double gx, gy, lv;
      if (groundAt(u, v, gx, gy, lv)) {
        // A pixel at level lv reads floor(lv) and floor(lv) + 1; neighbours within a grid cell
        // differ by a fraction of a level.
        const int la = std::clamp(static_cast<int>(std::floor(lv - 0.3)), 0, maxLevel);
        const int lb = std::clamp(static_cast<int>(std::floor(lv + 0.3)) + 1, 0, maxLevel);
        for (int l = la; l <= lb; ++l) {
          GroundBox& b = boxes[static_cast<std::size_t>(l)];
          b.x0 = std::min(b.x0, gx);
          b.x1 = std::max(b.x1, gx);
          b.y0 = std::min(b.y0, gy);
          b.y1 = std::max(b.y1, gy);
        }
      }
      if (u == rays.w - 1) break;
    }
    if (v == rays.h - 1) break;
  }
  return boxes;
}

/// The level views of a frame: per mip level the tiles over its ground extent and a margin,
/// relative to the frame origin (ox, oy). A level with an empty or absurdly large extent (grazing
/// view) gets no tiles: its pixels take the slow path.
std::vector<LevelView> levelViews(const std::vector<GroundBox>& boxes, const GroundTexture& tex, double ox, double oy) {
  std::vector<LevelView> views(boxes.size());
  for (std::size_t l = 0; l < views.size(); ++l) {
    LevelView& view = views[l];
    view.level = static_cast<int>(l);
    const double s = tex.texelSize(static_cast<int>(l));
    view.inv = static_cast<float>(1.0 / s);
    const GroundBox& b = boxes[l];
    if (b.x0 > b.x1) continue;
    // Margin: the ground spacing of the planning grid at this level (kPlanStep pixels of about a
    // texel each, more at grazing angles) and a bit.
    const double m = (2.0 * kPlanStep + 2.0) * s;
    const std::int64_t tx0 = floorDivTile(static_cast<std::int64_t>(std::floor((b.x0 - m) / s)));
    const std::int64_t ty0 = floorDivTile(static_cast<std::int64_t>(std::floor((b.y0 - m) / s)));
    const std::int64_t tx1 = floorDivTile(static_cast<std::int64_t>(std::floor((b.x1 + m) / s)));
    const std::int64_t ty1 = floorDivTile(static_cast<std::int64_t>(std::floor((b.y1 + m) / s)));
    if ((tx1 - tx0 + 1) * (ty1 - ty0 + 1) > 4096) continue;  // absurd (grazing view): slow path
    view.nx = static_cast<int>(tx1 - tx0 + 1);
    view.ny = static_cast<int>(ty1 - ty0 + 1);
    view.offX = static_cast<float>(ox / s - 0.5 - static_cast<double>(tx0 * kTile));
    view.offY = static_cast<float>(oy / s - 0.5 - static_cast<double>(ty0 * kTile));
    view.tiles.reserve(static_cast<std::size_t>(view.nx) * view.ny);
    for (std::int64_t ty = ty0; ty <= ty1; ++ty)
      for (std::int64_t tx = tx0; tx <= tx1; ++tx) {
        view.tiles.push_back(tex.tile(static_cast<int>(l), tx, ty));
        view.data.push_back(view.tiles.back()->texels.data());
      }
  }
  return views;
}

#ifdef GVINS_SIM_HAVE_AVX2_KERNEL
/// The AVX2 kernel's tables of a frame's level views. The kernel addresses the texels of all
/// views by 32-bit offsets from one base texel pointer (views whose tiles lie further apart in
/// memory are left to the scalar loop). The row fields of `kern` are the caller's.
struct KernelViews {
  RowKernel kern{};
  std::vector<float> inv, offX, offY;
  std::vector<int> nx, ny;
  std::vector<std::vector<std::int32_t>> off;
  std::vector<const std::int32_t*> offPtr;

  KernelViews(const std::vector<LevelView>& views, float maxRange, float l2s0, float maxL, float weight, int maxLevel)
      : inv(views.size()), offX(views.size()), offY(views.size()), nx(views.size()), ny(views.size()),
        off(views.size()), offPtr(views.size(), nullptr) {
    const float* base = nullptr;
    for (const LevelView& view : views)
      if (!view.data.empty()) {
        base = view.data.front();
        break;
      }
    for (std::size_t l = 0; l < views.size(); ++l) {
      const LevelView& view = views[l];
      inv[l] = view.inv;
      offX[l] = view.offX;
      offY[l] = view.offY;
      nx[l] = view.nx;
      ny[l] = view.ny;
      if (view.data.empty() || !base) continue;
      std::vector<std::int32_t>& o = off[l];
      for (const float* d : view.data) {
        const std::intptr_t bytes = reinterpret_cast<std::intptr_t>(d) - reinterpret_cast<std::intptr_t>(base);
        constexpr std::intptr_t kLimit = (std::intptr_t{1} << 31) - 2 * static_cast<std::intptr_t>(kStride * kStride);
        if (bytes % static_cast<std::intptr_t>(sizeof(float)) != 0 || bytes / 4 > kLimit || bytes / 4 < -kLimit) break;
        o.push_back(static_cast<std::int32_t>(bytes / 4));
      }
      if (o.size() == view.data.size()) offPtr[l] = o.data();
    }
    kern.base = base;
    kern.inv = inv.data();
    kern.offX = offX.data();
    kern.offY = offY.data();
    kern.nx = nx.data();
    kern.ny = ny.data();
    kern.tileOff = offPtr.data();
    kern.maxRange = maxRange;
    kern.l2s0 = l2s0;
    kern.maxL = maxL;
    kern.weight = weight;
    kern.maxLevel = maxLevel;
  }
  KernelViews(const KernelViews&) = delete;
  KernelViews& operator=(const KernelViews&) = delete;
};
#endif

}  // namespace

void ImagingConfig::validate() const {
  auto nonneg = [](double x) { return std::isfinite(x) && x >= 0.0; };
  if (!nonneg(exposure) || exposure > 1.0) throw std::invalid_argument("imaging: exposure must be in [0, 1] s");
  if (!nonneg(lineTime) || lineTime > 1e-3) throw std::invalid_argument("imaging: line time must be in [0, 1e-3] s");
  if (maxBlurSamples < 1 || maxBlurSamples > 64) throw std::invalid_argument("imaging: max blur samples in [1, 64]");
  if (!(blurStepPx > 0.01) || !std::isfinite(blurStepPx)) throw std::invalid_argument("imaging: blur step > 0.01 px");
  if (!nonneg(opticalBlurSigma) || opticalBlurSigma > 10.0) throw std::invalid_argument("imaging: PSF sigma in [0, 10] px");
  if (!nonneg(vignetting) || vignetting > 1.0) throw std::invalid_argument("imaging: vignetting in [0, 1]");
  if (!nonneg(gainSigma) || gainSigma > 1.0) throw std::invalid_argument("imaging: gain sigma in [0, 1]");
  if (!nonneg(gainCorrelation) || gainCorrelation > 1.0) throw std::invalid_argument("imaging: gain correlation in [0, 1]");
  if (!nonneg(readNoise) || readNoise > 100.0 || !nonneg(shotNoise) || shotNoise > 10.0)
    throw std::invalid_argument("imaging: noise out of range");
  if (!nonneg(sky) || sky > 255.0) throw std::invalid_argument("imaging: sky gray level in [0, 255]");
  if (!(maxRange > 0.0) || !std::isfinite(maxRange)) throw std::invalid_argument("imaging: max range must be positive");
}

CameraRenderer::CameraRenderer(const vio::CameraCalibration& camera, const ImagingConfig& imaging,
                               const GroundTexture& texture)
    : calib_(camera), model_(camera.intrinsics), img_(imaging), tex_(texture) {
  img_.validate();
  w_ = camera.intrinsics.width;
  h_ = camera.intrinsics.height;
  if (w_ < 8 || h_ < 8 || w_ > 8192 || h_ > 8192) throw std::invalid_argument("CameraRenderer: image size out of range");
  R_BC_ = camera.T_BS.topLeftCorner<3, 3>();
  p_BC_ = camera.T_BS.topRightCorner<3, 1>();
  const std::size_t n = static_cast<std::size_t>(w_) * h_;
  rayX_.resize(n);
  rayY_.resize(n);
  rayNorm_.resize(n);
  pixelAngle_.resize(n);
  vignette_.resize(n);
  for (int v = 0; v < h_; ++v)
    for (int u = 0; u < w_; ++u) {
      Eigen::Matrix2d J;
      const Eigen::Vector2d xn = model_.undistort(Eigen::Vector2d(u, v), &J);
      const std::size_t i = static_cast<std::size_t>(v) * w_ + u;
      const double r = std::sqrt(1.0 + xn.squaredNorm());
      rayX_[i] = static_cast<float>(xn.x());
      rayY_[i] = static_cast<float>(xn.y());
      rayNorm_[i] = static_cast<float>(r);
      // Solid angle of the pixel: |det d(x,y)/d(u,v)| / r^3 (dOmega = dx dy / r^3 on z = 1).
      pixelAngle_[i] = static_cast<float>(std::sqrt(std::abs(J.determinant()) / (r * r * r)));
      const double c = 1.0 / r;  // cos of the off-axis angle
      vignette_[i] = static_cast<float>(1.0 - img_.vignetting * (1.0 - c * c * c * c));
    }
}

void CameraRenderer::cameraPose(const TrajectoryState& s, Eigen::Matrix3d& R_WC, Eigen::Vector3d& p_WC) const {
  R_WC = s.R_WB * R_BC_;
  p_WC = s.p_WB + s.R_WB * p_BC_;
}

void CameraRenderer::accumulate(const std::vector<RowPose>& rows, float weight, float* out) const {
  const double log2s0 = std::log2(tex_.texelSize(0));
  const int maxLevel = tex_.levels() - 1;
  auto poseOf = [&](int v) -> const RowPose& { return rows.size() == 1 ? rows[0] : rows[static_cast<std::size_t>(v)]; };
  // Frame origin: the camera position of the first row, rounded to a metre (keeps the float
  // ground offsets small).
  const double ox = std::round(rows[0].p.x()), oy = std::round(rows[0].p.y());

  // The tiles this frame needs: ground points and levels on a coarse pixel grid.
  const PixelRays rays{rayX_.data(), rayY_.data(), rayNorm_.data(), pixelAngle_.data(), w_, h_};
  const std::vector<LevelView> views = levelViews(groundExtents(poseOf, rays, img_.maxRange, log2s0, maxLevel), tex_, ox, oy);

  const auto sky = static_cast<float>(img_.sky);
  const auto maxRange = static_cast<float>(img_.maxRange);
  const auto l2s0 = static_cast<float>(log2s0);
  const auto maxL = static_cast<float>(maxLevel);

#ifdef GVINS_SIM_HAVE_AVX2_KERNEL
  std::optional<KernelViews> simd;
  if (vectorized_ && cpuHasAvx2()) simd.emplace(views, maxRange, l2s0, maxL, weight, maxLevel);
  std::vector<int> failed(static_cast<std::size_t>(w_ / 8 + 1));
#endif

  for (int v = 0; v < h_; ++v) {
    const RowPose& P = poseOf(v);
    const auto r00 = static_cast<float>(P.R(0, 0)), r01 = static_cast<float>(P.R(0, 1)), r02 = static_cast<float>(P.R(0, 2));
    const auto r10 = static_cast<float>(P.R(1, 0)), r11 = static_cast<float>(P.R(1, 1)), r12 = static_cast<float>(P.R(1, 2));
    const auto r20 = static_cast<float>(P.R(2, 0)), r21 = static_cast<float>(P.R(2, 1)), r22 = static_cast<float>(P.R(2, 2));
    const auto cx = static_cast<float>(P.p.x() - ox), cy = static_cast<float>(P.p.y() - oy);
    const auto cz = static_cast<float>(P.p.z());
    const std::size_t base = static_cast<std::size_t>(v) * w_;
    auto pixel = [&](int u) {
      const std::size_t i = base + u;
      const float x = rayX_[i], y = rayY_[i];
      const float dz = r20 * x + r21 * y + r22;
      float val = sky;
      if (dz < -1e-6f && cz > 0.0f) {
        const float lam = -cz / dz;
        const float rn = rayNorm_[i];
        const float dist = lam * rn;
        if (dist <= maxRange) {
          const float gx = cx + lam * (r00 * x + r01 * y + r02);
          const float gy = cy + lam * (r10 * x + r11 * y + r12);
          const float cosInc = -dz / rn;
          float level = fastLog2(dist * pixelAngle_[i] / std::sqrt(cosInc)) - l2s0;
          level = std::clamp(level, 0.0f, maxL);
          const int l0 = static_cast<int>(level);
          const float f = level - static_cast<float>(l0);
          auto slow = [&](int lv) { return tex_.sampleLevel(ox + gx, oy + gy, lv); };
          val = sampleView(views[static_cast<std::size_t>(l0)], gx, gy, slow);
          if (f > 1e-3f && l0 < maxLevel)
            val = (1.0f - f) * val + f * sampleView(views[static_cast<std::size_t>(l0 + 1)], gx, gy, slow);
        }
      }
      out[i] += weight * val;
    };
    int u0 = 0;
#ifdef GVINS_SIM_HAVE_AVX2_KERNEL
    if (simd && simd->kern.base) {
      RowKernel& kern = simd->kern;
      kern.r00 = r00, kern.r01 = r01, kern.r02 = r02;
      kern.r10 = r10, kern.r11 = r11, kern.r12 = r12;
      kern.r20 = r20, kern.r21 = r21, kern.r22 = r22;
      kern.cx = cx, kern.cy = cy, kern.cz = cz;
      const int nFailed = accumulateRowAvx2(kern, rayX_.data() + base, rayY_.data() + base, rayNorm_.data() + base,
                                            pixelAngle_.data() + base, out + base, w_, failed.data());
      for (int b = 0; b < nFailed; ++b)
        for (int u = failed[static_cast<std::size_t>(b)]; u < failed[static_cast<std::size_t>(b)] + 8; ++u) pixel(u);
      u0 = w_ / 8 * 8;
    }
#endif
    for (int u = u0; u < w_; ++u) pixel(u);
  }
}

int CameraRenderer::blurSamples(const Trajectory& trajectory, double t) const {
  if (!img_.motionBlur || img_.exposure <= 0.0) return 1;
  Eigen::Matrix3d Ra, Rb;
  Eigen::Vector3d pa, pb;
  cameraPose(trajectory.evaluate(t - 0.5 * img_.exposure), Ra, pa);
  cameraPose(trajectory.evaluate(t + 0.5 * img_.exposure), Rb, pb);
  double maxMotion = 0.0;
  const Eigen::Vector2d probes[5] = {{0.5 * w_, 0.5 * h_}, {0, 0}, {w_ - 1.0, 0}, {0, h_ - 1.0}, {w_ - 1.0, h_ - 1.0}};
  for (const auto& px : probes) {
    const Eigen::Vector3d d = Ra * model_.bearing(px);
    // Point seen at px at the start: on the ground, or 1 km away for rays above the horizon.
    const double lam = (d.z() < -1e-6 && pa.z() > 0.0) ? std::min(-pa.z() / d.z(), 1000.0) : 1000.0;
    const Eigen::Vector3d X = pa + lam * d;
    const auto q = model_.project(Rb.transpose() * (X - pb));
    maxMotion = std::max(maxMotion, q ? (*q - px).norm() : 1e3);
  }
  return std::clamp(static_cast<int>(std::ceil(maxMotion / img_.blurStepPx)), 1, img_.maxBlurSamples);
}

cv::Mat CameraRenderer::render(const Trajectory& trajectory, double t, double gain, std::uint64_t noiseSeed) const {
  const int n = blurSamples(trajectory, t);
  cv::Mat acc(h_, w_, CV_32FC1, cv::Scalar(0.0f));
  auto* out = acc.ptr<float>();
  std::vector<RowPose> rows(img_.lineTime > 0.0 ? static_cast<std::size_t>(h_) : 1);
  for (int k = 0; k < n; ++k) {
    const double tk = t + img_.exposure * ((k + 0.5) / n - 0.5);
    for (std::size_t r = 0; r < rows.size(); ++r) {
      const double tr = tk + (rows.size() == 1 ? 0.0 : (static_cast<double>(r) - 0.5 * (h_ - 1)) * img_.lineTime);
      cameraPose(trajectory.evaluate(tr), rows[r].R, rows[r].p);
    }
    accumulate(rows, 1.0f / static_cast<float>(n), out);
  }
  const auto g = static_cast<float>(img_.noise ? gain : 1.0);
  const std::size_t np = static_cast<std::size_t>(w_) * h_;
  for (std::size_t i = 0; i < np; ++i) out[i] *= g * vignette_[i];
  if (img_.opticalBlurSigma > 0.0) cv::GaussianBlur(acc, acc, cv::Size(0, 0), img_.opticalBlurSigma);

  cv::Mat img(h_, w_, CV_8UC1);
  auto* dst = img.ptr<std::uint8_t>();
  const auto& table = normalTable().v;
  std::uint64_t state = hashCombine(noiseSeed, 0x1AB);
  std::uint64_t bits = 0;
  int left = 0;
  const auto read2 = static_cast<float>(img_.readNoise * img_.readNoise);
  const auto shot = static_cast<float>(img_.shotNoise);
  for (std::size_t i = 0; i < np; ++i) {
    float v = out[i];
    if (img_.noise) {
      if (left == 0) {
        bits = splitmix64(state);
        left = 5;
      }
      const float z = table[bits & 4095u];
      bits >>= 12;
      --left;
      v += std::sqrt(read2 + shot * std::max(v, 0.0f)) * z;
    }
    dst[i] = static_cast<std::uint8_t>(static_cast<int>(std::clamp(v, 0.0f, 255.0f) + 0.5f));
  }
  return img;
}

cv::Mat CameraRenderer::renderRadiance(const Eigen::Matrix3d& R_WC, const Eigen::Vector3d& p_WC) const {
  cv::Mat acc(h_, w_, CV_32FC1, cv::Scalar(0.0f));
  std::vector<RowPose> rows(1);
  rows[0].R = R_WC;
  rows[0].p = p_WC;
  accumulate(rows, 1.0f, acc.ptr<float>());
  return acc;
}

std::vector<double> exposureGains(std::size_t frames, const ImagingConfig& imaging, std::uint64_t seed) {
  std::vector<double> g(frames, 1.0);
  if (!imaging.noise || imaging.gainSigma <= 0.0) return g;
  Rng rng(seed, nameHash("exposure gain"));
  const double rho = imaging.gainCorrelation;
  double x = rng.normal(imaging.gainSigma);
  for (std::size_t k = 0; k < frames; ++k) {
    if (k > 0) x = rho * x + std::sqrt(1.0 - rho * rho) * rng.normal(imaging.gainSigma);
    g[k] = std::exp(x);
  }
  return g;
}

}  // namespace gvins::sim
