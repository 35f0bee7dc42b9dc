#include "gvins/sim/feature_simulator.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "gvins/sim/random.hpp"
#include "gvins/sim/urban_structure.hpp"

namespace gvins::sim {
namespace {
// Landmark ids: (i + 2^20) << 31 | (j + 2^20) << 10 | k for cell (i, j) and index k, below
// 2^52 (exact in a double); cells within +-2^20 of the origin.
constexpr std::int64_t kCellBias = std::int64_t{1} << 20;
constexpr int kMaxPerCell = (1 << 10) - 1;
}  // namespace

LandmarkField::LandmarkField(double densityPerM2, double heightSigma, std::uint64_t seed)
    : density_(densityPerM2), heightSigma_(heightSigma), seed_(seed) {
  if (!(densityPerM2 > 0.0 && densityPerM2 <= 1000.0)) throw std::invalid_argument("landmarks: density must be in (0, 1000] per m^2");
  if (!(heightSigma >= 0.0) || !std::isfinite(heightSigma)) throw std::invalid_argument("landmarks: height sigma must be >= 0");
  cell_ = std::sqrt(4.0 / density_);  // about 4 landmarks per cell
}

void LandmarkField::query(double x0, double y0, double x1, double y1, std::vector<Landmark>& out) const {
  if (!(x1 >= x0) || !(y1 >= y0) || !std::isfinite(x0 + x1 + y0 + y1)) return;
  if ((x1 - x0) * (y1 - y0) * density_ > 1e7) throw std::invalid_argument("landmarks: query region too large");
  const double lim = static_cast<double>(kCellBias - 2) * cell_;
  if (std::abs(x0) > lim || std::abs(x1) > lim || std::abs(y0) > lim || std::abs(y1) > lim)
    throw std::invalid_argument("landmarks: region too far from the origin");
  const auto i0 = static_cast<std::int64_t>(std::floor(x0 / cell_)), i1 = static_cast<std::int64_t>(std::floor(x1 / cell_));
  const auto j0 = static_cast<std::int64_t>(std::floor(y0 / cell_)), j1 = static_cast<std::int64_t>(std::floor(y1 / cell_));
  const double perCell = density_ * cell_ * cell_;
  for (std::int64_t j = j0; j <= j1; ++j)
    for (std::int64_t i = i0; i <= i1; ++i) {
      std::uint64_t st = hash4(seed_ ^ 0x1A9D3A2CULL, i, j, 0x4C4D);
      const int n = std::min(kMaxPerCell, static_cast<int>(std::floor(perCell + unitFromBits(splitmix64(st)))));
      for (int k = 0; k < n; ++k) {
        Landmark l;
        const double ux = unitFromBits(splitmix64(st)), uy = unitFromBits(splitmix64(st));
        l.p_W.x() = (static_cast<double>(i) + ux) * cell_;
        l.p_W.y() = (static_cast<double>(j) + uy) * cell_;
        if (heightSigma_ > 0.0) {
          // |N(0, sigma)| from two uniforms (Box-Muller radius, cosine part).
          const double u1 = 1.0 - unitFromBits(splitmix64(st)), u2 = unitFromBits(splitmix64(st));
          l.p_W.z() = heightSigma_ * std::abs(std::sqrt(-2.0 * std::log(u1)) * std::cos(6.283185307179586 * u2));
        }
        l.priority = unitFromBits(splitmix64(st));
        if (l.p_W.x() < x0 || l.p_W.x() > x1 || l.p_W.y() < y0 || l.p_W.y() > y1) continue;
        l.id = (static_cast<std::uint64_t>(i + kCellBias) << 31) | (static_cast<std::uint64_t>(j + kCellBias) << 10) |
               static_cast<std::uint64_t>(k);
        out.push_back(l);
      }
    }
}

void FeatureSimConfig::validate() const {
  auto nonneg = [](double x) { return std::isfinite(x) && x >= 0.0; };
  if (maxPerImage < 1 || maxPerImage > 100000) throw std::invalid_argument("features: max_per_image in [1, 100000]");
  if (!(landmarksPerImage > 0.0) || landmarksPerImage > 1e6) throw std::invalid_argument("features: landmarks_per_image in (0, 1e6]");
  if (!nonneg(densityPerM2) || densityPerM2 > 1000.0) throw std::invalid_argument("features: density in [0, 1000] per m^2");
  if (!nonneg(heightSigma) || heightSigma > 1000.0) throw std::invalid_argument("features: height sigma in [0, 1000] m");
  if (!nonneg(pixelNoise) || pixelNoise > 100.0) throw std::invalid_argument("features: pixel noise in [0, 100] px");
  if (!nonneg(outlierRate) || outlierRate > 1.0) throw std::invalid_argument("features: outlier rate in [0, 1]");
  if (!nonneg(outlierOffset) || outlierOffset > 1000.0) throw std::invalid_argument("features: outlier offset in [0, 1000] px");
  if (!nonneg(border) || border > 100.0) throw std::invalid_argument("features: border in [0, 100] px");
  if (!(maxRange > 0.0) || !std::isfinite(maxRange)) throw std::invalid_argument("features: max range must be positive");
}

FeatureSimulator::FeatureSimulator(const vio::CameraCalibration& camera, const FeatureSimConfig& config,
                                   const LandmarkField& field, double lineTime)
    : calib_(camera), model_(camera.intrinsics), cfg_(config), field_(&field), lineTime_(lineTime) {
  cfg_.validate();
  R_BC_ = camera.T_BS.topLeftCorner<3, 3>();
  p_BC_ = camera.T_BS.topRightCorner<3, 1>();
}

FeatureSimulator::FeatureSimulator(const vio::CameraCalibration& camera, const FeatureSimConfig& config,
                                   const UrbanStructure& world, double lineTime)
    : calib_(camera), model_(camera.intrinsics), cfg_(config), world_(&world), lineTime_(lineTime) {
  cfg_.validate();
  R_BC_ = camera.T_BS.topLeftCorner<3, 3>();
  p_BC_ = camera.T_BS.topRightCorner<3, 1>();
}

void FeatureSimulator::structureCandidates(const Eigen::Matrix3d& R_WC, const Eigen::Vector3d& p_WC,
                                           std::vector<Landmark>& lms, std::vector<int>& buildings) const {
  // Horizontal footprint of the frustum: the camera and the rays through the image border at
  // the maximum range.
  const int W = calib_.intrinsics.width, H = calib_.intrinsics.height;
  Eigen::AlignedBox2d box(Eigen::Vector2d(p_WC.head<2>()));
  for (int k = 0; k <= 16; ++k) {
    const double f = k / 16.0;
    const Eigen::Vector2d border[4] = {{f * (W - 1), 0.0}, {f * (W - 1), H - 1.0}, {0.0, f * (H - 1)}, {W - 1.0, f * (H - 1)}};
    for (const auto& px : border) {
      const Eigen::Vector3d d = R_WC * model_.bearing(px).normalized();
      box.extend(Eigen::Vector2d((p_WC + cfg_.maxRange * d).head<2>()));
    }
  }
  world_->landmarks(box, lms);
  world_->buildingsIn(box, buildings);
}

bool FeatureSimulator::project(const Trajectory& trajectory, double t, const Eigen::Vector3d& p_W,
                               Eigen::Vector2d& pixel) const {
  double row = 0.5 * (calib_.intrinsics.height - 1);
  for (int it = 0; it < (lineTime_ > 0.0 ? 4 : 1); ++it) {
    const double tr = t + (row - 0.5 * (calib_.intrinsics.height - 1)) * lineTime_;
    const TrajectoryState s = trajectory.evaluate(tr);
    const Eigen::Matrix3d R_WC = s.R_WB * R_BC_;
    const Eigen::Vector3d p_WC = s.p_WB + s.R_WB * p_BC_;
    const auto q = model_.project(R_WC.transpose() * (p_W - p_WC));
    if (!q) return false;
    pixel = *q;
    row = std::clamp(q->y(), 0.0, static_cast<double>(calib_.intrinsics.height - 1));
  }
  return true;
}

std::vector<FeatureObservation> FeatureSimulator::observe(const Trajectory& trajectory, double t,
                                                          std::uint64_t noiseSeed) const {
  const TrajectoryState s = trajectory.evaluate(t);
  const Eigen::Matrix3d R_WC = s.R_WB * R_BC_;
  const Eigen::Vector3d p_WC = s.p_WB + s.R_WB * p_BC_;
  const int W = calib_.intrinsics.width, H = calib_.intrinsics.height;
  std::vector<Landmark> lms;
  std::vector<int> buildings;
  if (world_) {
    structureCandidates(R_WC, p_WC, lms, buildings);
  } else {
    // Ground region in view: rays through the image border, clipped at the maximum range.
    double x0 = p_WC.x(), x1 = p_WC.x(), y0 = p_WC.y(), y1 = p_WC.y();
    const double hMax = 3.0 * cfg_.heightSigma;  // landmarks are at most this high (3 sigma)
    for (int k = 0; k <= 32; ++k) {
      const double f = k / 32.0;
      const Eigen::Vector2d border[4] = {{f * (W - 1), 0.0}, {f * (W - 1), H - 1.0}, {0.0, f * (H - 1)}, {W - 1.0, f * (H - 1)}};
      for (const auto& px : border) {
        const Eigen::Vector3d d = R_WC * model_.bearing(px);
        double lam = cfg_.maxRange;
        if (d.z() < -1e-9) lam = std::min(lam, (p_WC.z() - 0.0) / -d.z());
        // Also the intersection with the top of the landmark layer (raised landmarks seen nearer).
        for (const double z : {0.0, hMax}) {
          const double l = d.z() < -1e-9 ? std::min(cfg_.maxRange, (p_WC.z() - z) / -d.z()) : lam;
          const Eigen::Vector3d g = p_WC + std::max(l, 0.0) * d;
          x0 = std::min(x0, g.x());
          x1 = std::max(x1, g.x());
          y0 = std::min(y0, g.y());
          y1 = std::max(y1, g.y());
        }
      }
    }
    const double margin = 2.0 + 0.05 * std::max(x1 - x0, y1 - y0);
    field_->query(x0 - margin, y0 - margin, x1 + margin, y1 + margin, lms);
  }

  struct Seen {
    const Landmark* l;
    Eigen::Vector2d px;
  };
  std::vector<Seen> seen;
  seen.reserve(lms.size());
  for (const Landmark& l : lms) {
    const Eigen::Vector3d pc = R_WC.transpose() * (l.p_W - p_WC);
    if (pc.z() <= 0.05 || pc.norm() > cfg_.maxRange) continue;
    Eigen::Vector2d px;
    if (lineTime_ > 0.0) {
      if (!project(trajectory, t, l.p_W, px)) continue;
    } else {
      const auto q = model_.project(pc);
      if (!q) continue;
      px = *q;
    }
    if (!model_.inImage(px, cfg_.border)) continue;
    // The equidistant model maps rays beyond 90 deg into the image too; keep rays in front.
    seen.push_back({&l, px});
  }
  std::sort(seen.begin(), seen.end(), [](const Seen& a, const Seen& b) {
    return a.l->priority != b.l->priority ? a.l->priority > b.l->priority : a.l->id < b.l->id;
  });
  if (world_) {
    // Occlusion by the buildings, tested in priority order until the image is full.
    std::size_t kept = 0;
    for (std::size_t i = 0; i < seen.size() && kept < static_cast<std::size_t>(cfg_.maxPerImage); ++i)
      if (!world_->segmentBlocked(p_WC, seen[i].l->p_W, buildings)) seen[kept++] = seen[i];
    seen.resize(kept);
  }
  if (seen.size() > static_cast<std::size_t>(cfg_.maxPerImage)) seen.resize(static_cast<std::size_t>(cfg_.maxPerImage));
  std::sort(seen.begin(), seen.end(), [](const Seen& a, const Seen& b) { return a.l->id < b.l->id; });

  Rng rng(noiseSeed, nameHash("feature noise"));
  std::vector<FeatureObservation> out;
  out.reserve(seen.size());
  for (const Seen& s2 : seen) {
    FeatureObservation o;
    o.landmark = s2.l->id;
    o.p_W = s2.l->p_W;
    o.truePixel = s2.px;
    o.pixel = s2.px + Eigen::Vector2d(rng.normal(cfg_.pixelNoise), rng.normal(cfg_.pixelNoise));
    if (cfg_.outlierRate > 0.0 && rng.uniform() < cfg_.outlierRate) {
      o.outlier = true;
      const Eigen::Vector2d off(rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0));
      o.pixel = s2.px + cfg_.outlierOffset * off;
      o.pixel.x() = std::clamp(o.pixel.x(), 0.0, W - 1.0);
      o.pixel.y() = std::clamp(o.pixel.y(), 0.0, H - 1.0);
    }
    out.push_back(o);
  }
  return out;
}

double autoLandmarkDensity(const vio::CameraIntrinsics& k, double height, double landmarksPerImage) {
  const double area = (k.width / k.fx) * (k.height / k.fy) * height * height;
  return std::clamp(landmarksPerImage / std::max(area, 1e-6), 1e-6, 1000.0);
}

}  // namespace gvins::sim
