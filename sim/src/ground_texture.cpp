#include "gvins/sim/ground_texture.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
#include <immintrin.h>
#endif

#include "gvins/sim/random.hpp"

namespace gvins::sim {
namespace {

constexpr double kPi = std::numbers::pi;

enum class ShapeType { Rectangle, Ellipse, Triangle };

struct Shape {
  ShapeType type = ShapeType::Rectangle;
  double cx = 0, cy = 0;   // centre
  double a = 0, b = 0;     // half sizes (rectangle, ellipse) / radius (triangle: a)
  double c = 1, s = 0;     // cos/sin of the orientation
  double amp = 0;          // brightness step
  double radius = 0;       // bounding radius
  double nx[3] = {0, 0, 0}, ny[3] = {0, 0, 0}, off[3] = {0, 0, 0};  // triangle edges n.p <= off
};

/// The shape of one cell, or false if the cell is empty.
bool cellShape(std::uint64_t seed, int octave, std::int64_t ci, std::int64_t cj, double cell, double amplitude,
               Shape& sh) {
  std::uint64_t st = hash4(seed ^ (0x51ED270B27AC5F1DULL * static_cast<std::uint64_t>(octave + 1)), ci, cj, octave);
  auto u = [&] { return unitFromBits(splitmix64(st)); };
  if (u() >= 0.8) return false;
  sh.cx = (static_cast<double>(ci) + u()) * cell;
  sh.cy = (static_cast<double>(cj) + u()) * cell;
  const double t = u();
  sh.type = t < 0.5 ? ShapeType::Rectangle : (t < 0.8 ? ShapeType::Ellipse : ShapeType::Triangle);
  sh.a = (0.12 + 0.38 * u()) * cell;
  sh.b = (0.12 + 0.38 * u()) * cell;
  const double ang = u() * kPi;
  sh.c = std::cos(ang);
  sh.s = std::sin(ang);
  sh.amp = (u() < 0.5 ? -1.0 : 1.0) * (0.5 + 0.5 * u()) * amplitude;
  switch (sh.type) {
    case ShapeType::Rectangle: sh.radius = std::hypot(sh.a, sh.b); break;
    case ShapeType::Ellipse: sh.radius = std::max(sh.a, sh.b); break;
    case ShapeType::Triangle: {
      const double r = std::max(sh.a, sh.b);
      sh.radius = r;
      const double th[3] = {ang, ang + 2.0 + 0.6 * u(), ang + 4.1 + 0.6 * u()};
      double vx[3], vy[3];
      for (int k = 0; k < 3; ++k) {
        vx[k] = sh.cx + r * std::cos(th[k]);
        vy[k] = sh.cy + r * std::sin(th[k]);
      }
      for (int k = 0; k < 3; ++k) {
        const int k1 = (k + 1) % 3;
        // Vertices counter-clockwise: outward normal of edge k -> k1 is (dy, -dx).
        double ex = vx[k1] - vx[k], ey = vy[k1] - vy[k];
        const double len = std::hypot(ex, ey);
        ex /= len;
        ey /= len;
        sh.nx[k] = ey;
        sh.ny[k] = -ex;
        sh.off[k] = sh.nx[k] * vx[k] + sh.ny[k] * vy[k];
      }
      break;
    }
  }
  return true;
}

/// Signed distance (negative inside) of a point to a shape (exact for rectangles, close for
/// ellipses and triangles near their edges, which is where it matters).
inline double signedDistance(const Shape& sh, double x, double y) {
  const double dx = x - sh.cx, dy = y - sh.cy;
  switch (sh.type) {
    case ShapeType::Rectangle: {
      const double lx = std::abs(sh.c * dx + sh.s * dy) - sh.a;
      const double ly = std::abs(-sh.s * dx + sh.c * dy) - sh.b;
      const double ox = std::max(lx, 0.0), oy = std::max(ly, 0.0);
      return std::sqrt(ox * ox + oy * oy) + std::min(std::max(lx, ly), 0.0);
    }
    case ShapeType::Ellipse: {
      const double lx = (sh.c * dx + sh.s * dy) / sh.a;
      const double ly = (-sh.s * dx + sh.c * dy) / sh.b;
      return (std::sqrt(lx * lx + ly * ly) - 1.0) * std::min(sh.a, sh.b);
    }
    case ShapeType::Triangle: {
      double d = -1e300;
      for (int k = 0; k < 3; ++k) d = std::max(d, sh.nx[k] * x + sh.ny[k] * y - sh.off[k]);
      return d;
    }
  }
  return 1e300;
}

inline double coverage(double sd, double texel) { return std::clamp(0.5 - sd / texel, 0.0, 1.0); }

/// Octave weight at a texel size: 0 below 2 texels per cell, 1 above 4 (smoothstep).
inline double octaveWeight(double cell, double texel) {
  const double x = std::clamp((cell / texel - 2.0) * 0.5, 0.0, 1.0);
  return x * x * (3.0 - 2.0 * x);
}

/// Integral of the square wave sgn(sin(pi u)) from 0 to u (a triangle wave in [0, 1]).
inline double squareWaveIntegral(double u) {
  const double m = u - 2.0 * std::floor(0.5 * u);
  return m < 1.0 ? m : 2.0 - m;
}
/// Box filter of sgn(sin(pi u)) over [u - w/2, u + w/2].
inline double filteredSquareWave(double u, double w) {
  if (w < 1e-9) return std::sin(kPi * u) >= 0.0 ? 1.0 : -1.0;
  return (squareWaveIntegral(u + 0.5 * w) - squareWaveIntegral(u - 0.5 * w)) / w;
}

/// Checkerboard overlay at a point for a texel size: returns the mixing weight (0 outside) and
/// the board value.
inline double boardOverlay(const CheckerboardConfig& b, double x, double y, double texel, double& value) {
  if (!b.enabled) return 0.0;
  const double yaw = b.yawDeg * kPi / 180.0, c = std::cos(yaw), s = std::sin(yaw);
  const double dx = x - b.origin.x(), dy = y - b.origin.y();
  const double bx = c * dx + s * dy, by = -s * dx + c * dy;
  const double q = b.square;
  // Outer rectangle (white border one square wide around the (cols+1) x (rows+1) squares).
  const double x0 = -2.0 * q, x1 = (b.innerCols + 1) * q, y0 = -2.0 * q, y1 = (b.innerRows + 1) * q;
  auto rectSd = [&](double ax0, double ax1, double ay0, double ay1) {
    const double lx = std::max(ax0 - bx, bx - ax1), ly = std::max(ay0 - by, by - ay1);
    const double ox = std::max(lx, 0.0), oy = std::max(ly, 0.0);
    return std::sqrt(ox * ox + oy * oy) + std::min(std::max(lx, ly), 0.0);
  };
  const double outer = coverage(rectSd(x0, x1, y0, y1), texel);
  if (outer <= 0.0) return 0.0;
  const double inner = coverage(rectSd(-q, b.innerCols * q, -q, b.innerRows * q), texel);
  const double w = texel / q;
  const double checker = filteredSquareWave(bx / q, w) * filteredSquareWave(by / q, w);
  const double mid = 0.5 * (b.dark + b.bright), half = 0.5 * (b.bright - b.dark);
  value = b.bright * (1.0 - inner) + (mid + half * checker) * inner;
  return outer;
}

/// row[i] += amp coverage(signedDistance(sh, xMin + i s, y), s) for i in [ia, ib].
inline void addShapeRowScalar(const Shape& sh, double y, double xMin, double s, int ia, int ib, double amp,
                              double* row) {
  for (int i = ia; i <= ib; ++i) row[i] += amp * coverage(signedDistance(sh, xMin + i * s, y), s);
}

#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
#define GVINS_SIM_HAVE_AVX2_TEXTURE 1
bool textureCpuHasAvx2() {
  static const bool has = __builtin_cpu_supports("avx2");
  return has;
}
/// addShapeRowScalar 4 texels at a time: the operations of signedDistance() and coverage() in
/// their order (std::max(a, b) = max_pd(b, a), std::min(a, b) = min_pd(b, a), std::clamp(v, 0,
/// 1) = max_pd(0, min_pd(1, v)); no FMA), so the same sums bit for bit.
__attribute__((target("avx2"))) void addShapeRowAvx2(const Shape& sh, double y, double xMin, double s, int ia, int ib,
                                                     double amp, double* row) {
  const __m256d vs = _mm256_set1_pd(s), vamp = _mm256_set1_pd(amp), half = _mm256_set1_pd(0.5);
  const __m256d zero = _mm256_setzero_pd(), one = _mm256_set1_pd(1.0), sign = _mm256_set1_pd(-0.0);
  const __m256d vxMin = _mm256_set1_pd(xMin), step = _mm256_set_pd(3.0, 2.0, 1.0, 0.0);
  const double dy = y - sh.cy;
  int i = ia;
  for (; i + 4 <= ib + 1; i += 4) {
    const __m256d fi = _mm256_add_pd(_mm256_set1_pd(static_cast<double>(i)), step);  // exact integers
    const __m256d x = _mm256_add_pd(vxMin, _mm256_mul_pd(fi, vs));
    __m256d sd;
    switch (sh.type) {
      case ShapeType::Rectangle: {
        const __m256d dx = _mm256_sub_pd(x, _mm256_set1_pd(sh.cx));
        const __m256d lx = _mm256_sub_pd(
            _mm256_andnot_pd(sign, _mm256_add_pd(_mm256_mul_pd(_mm256_set1_pd(sh.c), dx), _mm256_set1_pd(sh.s * dy))),
            _mm256_set1_pd(sh.a));
        const __m256d ly = _mm256_sub_pd(
            _mm256_andnot_pd(sign, _mm256_add_pd(_mm256_mul_pd(_mm256_set1_pd(-sh.s), dx), _mm256_set1_pd(sh.c * dy))),
            _mm256_set1_pd(sh.b));
        const __m256d ox = _mm256_max_pd(zero, lx), oy = _mm256_max_pd(zero, ly);
        sd = _mm256_add_pd(_mm256_sqrt_pd(_mm256_add_pd(_mm256_mul_pd(ox, ox), _mm256_mul_pd(oy, oy))),
                           _mm256_min_pd(zero, _mm256_max_pd(ly, lx)));
        break;
      }
      case ShapeType::Ellipse: {
        const __m256d dx = _mm256_sub_pd(x, _mm256_set1_pd(sh.cx));
        const __m256d lx = _mm256_div_pd(_mm256_add_pd(_mm256_mul_pd(_mm256_set1_pd(sh.c), dx), _mm256_set1_pd(sh.s * dy)),
                                         _mm256_set1_pd(sh.a));
        const __m256d ly = _mm256_div_pd(_mm256_add_pd(_mm256_mul_pd(_mm256_set1_pd(-sh.s), dx), _mm256_set1_pd(sh.c * dy)),
                                         _mm256_set1_pd(sh.b));
        sd = _mm256_mul_pd(_mm256_sub_pd(_mm256_sqrt_pd(_mm256_add_pd(_mm256_mul_pd(lx, lx), _mm256_mul_pd(ly, ly))), one),
                           _mm256_set1_pd(std::min(sh.a, sh.b)));
        break;
      }
      default: {  // triangle
        sd = _mm256_set1_pd(-1e300);
        for (int k = 0; k < 3; ++k) {
          const __m256d e = _mm256_sub_pd(_mm256_add_pd(_mm256_mul_pd(_mm256_set1_pd(sh.nx[k]), x), _mm256_set1_pd(sh.ny[k] * y)),
                                          _mm256_set1_pd(sh.off[k]));
          sd = _mm256_max_pd(e, sd);
        }
        break;
      }
    }
    const __m256d cov = _mm256_max_pd(zero, _mm256_min_pd(one, _mm256_sub_pd(half, _mm256_div_pd(sd, vs))));
    _mm256_storeu_pd(row + i, _mm256_add_pd(_mm256_loadu_pd(row + i), _mm256_mul_pd(vamp, cov)));
  }
  addShapeRowScalar(sh, y, xMin, s, i, ib, amp, row);
}
#endif

inline void addShapeRow(const Shape& sh, double y, double xMin, double s, int ia, int ib, double amp, double* row) {
#ifdef GVINS_SIM_HAVE_AVX2_TEXTURE
  if (textureCpuHasAvx2()) return addShapeRowAvx2(sh, y, xMin, s, ia, ib, amp, row);
#endif
  addShapeRowScalar(sh, y, xMin, s, ia, ib, amp, row);
}

std::int64_t floorDiv(std::int64_t a, std::int64_t b) {
  const std::int64_t q = a / b;
  return (a % b != 0 && ((a < 0) != (b < 0))) ? q - 1 : q;
}

std::uint64_t tileKey(int level, std::int64_t tx, std::int64_t ty) {
  return hash4(static_cast<std::uint64_t>(level), tx, ty, 0x7117);
}

}  // namespace

Eigen::Vector2d CheckerboardConfig::corner(int i, int j) const {
  const double yaw = yawDeg * kPi / 180.0;
  const Eigen::Vector2d local(i * square, j * square);
  return origin + Eigen::Vector2d(std::cos(yaw) * local.x() - std::sin(yaw) * local.y(),
                                  std::sin(yaw) * local.x() + std::cos(yaw) * local.y());
}

void GroundTextureConfig::validate() const {
  if (!(texelSize > 0.0) || !std::isfinite(texelSize) || !(finestFeature > 0.0) || !std::isfinite(finestFeature))
    throw std::invalid_argument("texture: texel and feature sizes must be positive");
  if (levels < 1 || levels > 24 || octaves < 1 || octaves > 24)
    throw std::invalid_argument("texture: levels and octaves must be in [1, 24]");
  if (!std::isfinite(mean) || !std::isfinite(amplitude) || amplitude < 0.0)
    throw std::invalid_argument("texture: mean/amplitude must be finite (amplitude >= 0)");
  if (board.enabled && (board.innerCols < 2 || board.innerRows < 2 || board.innerCols > 100 ||
                        board.innerRows > 100 || !(board.square > 0.0) || !board.origin.allFinite()))
    throw std::invalid_argument("texture: checkerboard needs 2-100 inner corners and a positive square");
}

GroundTexture::GroundTexture(const GroundTextureConfig& config) : cfg_(config) {
  cfg_.validate();
  for (int l = 0; l < cfg_.levels; ++l) texel_.push_back(cfg_.texelSize * std::ldexp(1.0, l));
}

float GroundTexture::texel(int level, std::int64_t i, std::int64_t j) const {
  const double s = texelSize(level);
  const double x = (static_cast<double>(i) + 0.5) * s, y = (static_cast<double>(j) + 0.5) * s;
  double v = cfg_.mean;
  for (int o = 0; o < cfg_.octaves; ++o) {
    const double cell = cfg_.finestFeature * std::ldexp(1.0, o);
    const double w = octaveWeight(cell, s);
    if (w <= 0.0) continue;
    const auto ci = static_cast<std::int64_t>(std::floor(x / cell)), cj = static_cast<std::int64_t>(std::floor(y / cell));
    for (std::int64_t a = ci - 1; a <= ci + 1; ++a)
      for (std::int64_t b = cj - 1; b <= cj + 1; ++b) {
        Shape sh;
        if (!cellShape(cfg_.seed, o, a, b, cell, cfg_.amplitude, sh)) continue;
        v += w * sh.amp * coverage(signedDistance(sh, x, y), s);
      }
  }
  double bv = 0.0;
  const double m = boardOverlay(cfg_.board, x, y, s, bv);
  v = v * (1.0 - m) + bv * m;
  return static_cast<float>(std::clamp(v, 0.0, 255.0));
}

void GroundTexture::renderTile(Tile& t) const {
  constexpr int n = kTileSize + 1;
  const double s = texelSize(t.level);
  const std::int64_t i0 = t.tx * kTileSize, j0 = t.ty * kTileSize;
  std::vector<double> acc(static_cast<std::size_t>(n) * n, cfg_.mean);
  const double xMin = (static_cast<double>(i0) + 0.5) * s, yMin = (static_cast<double>(j0) + 0.5) * s;
  const double xMax = xMin + (n - 1) * s, yMax = yMin + (n - 1) * s;
  for (int o = 0; o < cfg_.octaves; ++o) {
    const double cell = cfg_.finestFeature * std::ldexp(1.0, o);
    const double w = octaveWeight(cell, s);
    if (w <= 0.0) continue;
    // Cells whose shapes (within 0.75 cell of the cell) can reach the tile.
    const auto ca = static_cast<std::int64_t>(std::floor(xMin / cell)) - 1;
    const auto cb = static_cast<std::int64_t>(std::floor(xMax / cell)) + 1;
    const auto da = static_cast<std::int64_t>(std::floor(yMin / cell)) - 1;
    const auto db = static_cast<std::int64_t>(std::floor(yMax / cell)) + 1;
    for (std::int64_t cj = da; cj <= db; ++cj)
      for (std::int64_t ci = ca; ci <= cb; ++ci) {
        Shape sh;
        if (!cellShape(cfg_.seed, o, ci, cj, cell, cfg_.amplitude, sh)) continue;
        const double r = sh.radius + s;
        const int ia = std::max(0, static_cast<int>(std::floor((sh.cx - r - xMin) / s)));
        const int ib = std::min(n - 1, static_cast<int>(std::ceil((sh.cx + r - xMin) / s)));
        const int ja = std::max(0, static_cast<int>(std::floor((sh.cy - r - yMin) / s)));
        const int jb = std::min(n - 1, static_cast<int>(std::ceil((sh.cy + r - yMin) / s)));
        const double amp = w * sh.amp;
        for (int j = ja; j <= jb; ++j) {
          const double y = yMin + j * s;
          double* row = acc.data() + static_cast<std::size_t>(j) * n;
          addShapeRow(sh, y, xMin, s, ia, ib, amp, row);
        }
      }
  }
  t.texels.resize(acc.size());
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      double v = acc[static_cast<std::size_t>(j) * n + i];
      double bv = 0.0;
      const double m = boardOverlay(cfg_.board, xMin + i * s, yMin + j * s, s, bv);
      v = v * (1.0 - m) + bv * m;
      t.texels[static_cast<std::size_t>(j) * n + i] = static_cast<float>(std::clamp(v, 0.0, 255.0));
    }
}

std::shared_ptr<const GroundTexture::Tile> GroundTexture::tile(int level, std::int64_t tx, std::int64_t ty) const {
  const std::uint64_t key = tileKey(level, tx, ty);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = cache_.find(key);
    if (it != cache_.end() && it->second.tile->level == level && it->second.tile->tx == tx && it->second.tile->ty == ty) {
      it->second.lastUse = ++useCounter_;
      return it->second.tile;
    }
  }
  auto t = std::make_shared<Tile>();
  t->level = level;
  t->tx = tx;
  t->ty = ty;
  renderTile(*t);
  std::lock_guard<std::mutex> lock(mutex_);
  ++generated_;
  const std::size_t tileBytes = t->texels.size() * sizeof(float) + sizeof(Tile);
  if ((cache_.size() + 1) * tileBytes > cfg_.cacheBytes && !cache_.empty()) {
    // Evict the least recently used half.
    std::vector<std::pair<std::uint64_t, std::uint64_t>> uses;
    uses.reserve(cache_.size());
    for (const auto& [k, e] : cache_) uses.emplace_back(e.lastUse, k);
    std::nth_element(uses.begin(), uses.begin() + static_cast<long>(uses.size() / 2), uses.end());
    for (std::size_t i = 0; i < uses.size() / 2 + 1 && i < uses.size(); ++i) cache_.erase(uses[i].second);
  }
  Entry& e = cache_[key];
  e.tile = t;
  e.lastUse = ++useCounter_;
  return t;
}

float GroundTexture::sampleLevel(double x, double y, int level) const {
  const double s = texelSize(level);
  const double fx = x / s - 0.5, fy = y / s - 0.5;
  const double flx = std::floor(fx), fly = std::floor(fy);
  const auto i = static_cast<std::int64_t>(flx), j = static_cast<std::int64_t>(fly);
  const std::int64_t tx = floorDiv(i, kTileSize), ty = floorDiv(j, kTileSize);
  const auto t = tile(level, tx, ty);
  const auto li = static_cast<std::size_t>(i - tx * kTileSize), lj = static_cast<std::size_t>(j - ty * kTileSize);
  constexpr std::size_t n = kTileSize + 1;
  const float* p = t->texels.data() + lj * n + li;
  const auto ax = static_cast<float>(fx - flx), ay = static_cast<float>(fy - fly);
  return (1 - ay) * ((1 - ax) * p[0] + ax * p[1]) + ay * ((1 - ax) * p[n] + ax * p[n + 1]);
}

float GroundTexture::sample(double x, double y, double level) const {
  const double l = std::clamp(level, 0.0, static_cast<double>(cfg_.levels - 1));
  const int l0 = static_cast<int>(std::floor(l));
  const double f = l - l0;
  const float a = sampleLevel(x, y, l0);
  if (f <= 0.0 || l0 + 1 >= cfg_.levels) return a;
  return static_cast<float>((1.0 - f) * a + f * sampleLevel(x, y, l0 + 1));
}

double GroundTexture::levelForFootprint(double size) const { return std::log2(size / cfg_.texelSize); }

std::size_t GroundTexture::tilesGenerated() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return generated_;
}

std::size_t GroundTexture::cachedBytes() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return cache_.size() * ((kTileSize + 1) * (kTileSize + 1) * sizeof(float) + sizeof(Tile));
}

}  // namespace gvins::sim
