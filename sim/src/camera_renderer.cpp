#include "gvins/sim/camera_renderer.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

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

  // Plan the tiles this frame needs: ground points and levels on a coarse pixel grid.
  constexpr int kStep = 16;
  struct Box {
    double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
  };
  std::vector<Box> boxes(static_cast<std::size_t>(maxLevel + 1));
  auto groundAt = [&](int u, int v, double& gx, double& gy, double& level) {
    const RowPose& P = poseOf(v);
    const std::size_t i = static_cast<std::size_t>(v) * w_ + u;
    const Eigen::Vector3d d = P.R * Eigen::Vector3d(rayX_[i], rayY_[i], 1.0);
    if (d.z() >= -1e-6 || P.p.z() <= 0.0) return false;
    const double lam = -P.p.z() / d.z();
    const double dist = lam * rayNorm_[i];
    if (dist > img_.maxRange) return false;
    gx = P.p.x() + lam * d.x();
    gy = P.p.y() + lam * d.y();
    const double cosInc = -d.z() / rayNorm_[i];
    level = std::log2(dist * pixelAngle_[i] / std::sqrt(cosInc)) - log2s0;
    return true;
  };
  for (int v = 0;; v = std::min(v + kStep, h_ - 1)) {
    for (int u = 0;; u = std::min(u + kStep, w_ - 1)) {
      double gx, gy, lv;
      if (groundAt(u, v, gx, gy, lv)) {
        // A pixel at level lv reads floor(lv) and floor(lv) + 1; neighbours within a grid cell
        // differ by a fraction of a level.
        const int la = std::clamp(static_cast<int>(std::floor(lv - 0.3)), 0, maxLevel);
        const int lb = std::clamp(static_cast<int>(std::floor(lv + 0.3)) + 1, 0, maxLevel);
        for (int l = la; l <= lb; ++l) {
          Box& b = boxes[static_cast<std::size_t>(l)];
          b.x0 = std::min(b.x0, gx);
          b.x1 = std::max(b.x1, gx);
          b.y0 = std::min(b.y0, gy);
          b.y1 = std::max(b.y1, gy);
        }
      }
      if (u == w_ - 1) break;
    }
    if (v == h_ - 1) break;
  }
  std::vector<LevelView> views(static_cast<std::size_t>(maxLevel + 1));
  for (int l = 0; l <= maxLevel; ++l) {
    LevelView& view = views[static_cast<std::size_t>(l)];
    view.level = l;
    const double s = tex_.texelSize(l);
    view.inv = static_cast<float>(1.0 / s);
    const Box& b = boxes[static_cast<std::size_t>(l)];
    if (b.x0 > b.x1) continue;
    // Margin: the ground spacing of the planning grid at this level (kStep pixels of about a
    // texel each, more at grazing angles) and a bit.
    const double m = (2.0 * kStep + 2.0) * s;
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
        view.tiles.push_back(tex_.tile(l, tx, ty));
        view.data.push_back(view.tiles.back()->texels.data());
      }
  }

  const auto sky = static_cast<float>(img_.sky);
  const auto maxRange = static_cast<float>(img_.maxRange);
  const auto l2s0 = static_cast<float>(log2s0);
  const auto maxL = static_cast<float>(maxLevel);
  for (int v = 0; v < h_; ++v) {
    const RowPose& P = poseOf(v);
    const auto r00 = static_cast<float>(P.R(0, 0)), r01 = static_cast<float>(P.R(0, 1)), r02 = static_cast<float>(P.R(0, 2));
    const auto r10 = static_cast<float>(P.R(1, 0)), r11 = static_cast<float>(P.R(1, 1)), r12 = static_cast<float>(P.R(1, 2));
    const auto r20 = static_cast<float>(P.R(2, 0)), r21 = static_cast<float>(P.R(2, 1)), r22 = static_cast<float>(P.R(2, 2));
    const auto cx = static_cast<float>(P.p.x() - ox), cy = static_cast<float>(P.p.y() - oy);
    const auto cz = static_cast<float>(P.p.z());
    const std::size_t base = static_cast<std::size_t>(v) * w_;
    for (int u = 0; u < w_; ++u) {
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
    }
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
