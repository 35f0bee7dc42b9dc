#include "gvins/vio/affine_patch.hpp"

#include <cmath>
#include <optional>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/SVD>

namespace gvins::vio {

namespace {

// Bilinear interpolation of an 8-bit image at (x, y); the caller keeps 0 <= x < cols − 1 and
// 0 <= y < rows − 1.
inline float sample(const cv::Mat& img, float x, float y) {
  const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
  const float ax = x - static_cast<float>(x0), ay = y - static_cast<float>(y0);
  const unsigned char* r0 = img.ptr<unsigned char>(y0) + x0;
  const unsigned char* r1 = r0 + img.step[0];
  const float top = static_cast<float>(r0[0]) + ax * (static_cast<float>(r0[1]) - static_cast<float>(r0[0]));
  const float bottom = static_cast<float>(r1[0]) + ax * (static_cast<float>(r1[1]) - static_cast<float>(r1[0]));
  return top + ay * (bottom - top);
}

inline bool inside(const cv::Mat& img, float x, float y) {
  return x >= 0.0f && y >= 0.0f && x < static_cast<float>(img.cols - 1) && y < static_cast<float>(img.rows - 1);
}

}  // namespace

bool AffinePatch::extract(const cv::Mat& image, const cv::Point2f& c, const PatchAlignParams& p) {
  centred_.resize(0);
  sd_.resize(6, 0);
  const int h = p.halfSize;
  if (h < 1 || image.empty() || image.type() != CV_8UC1) return false;
  const float e = static_cast<float>(h + 1);
  if (!inside(image, c.x - e, c.y - e) || !inside(image, c.x + e, c.y + e)) return false;
  const int w = 2 * h + 3;  // samples with a one-pixel border for the central differences
  std::vector<float> s(static_cast<std::size_t>(w * w));
  for (int v = -h - 1; v <= h + 1; ++v) {
    for (int u = -h - 1; u <= h + 1; ++u) {
      s[static_cast<std::size_t>((v + h + 1) * w + u + h + 1)] =
          sample(image, c.x + static_cast<float>(u), c.y + static_cast<float>(v));
    }
  }
  const int n = 2 * h + 1;
  Eigen::VectorXf values(n * n);
  Eigen::Matrix<float, 6, Eigen::Dynamic, Eigen::RowMajor> sd(6, n * n);
  for (int v = -h; v <= h; ++v) {
    for (int u = -h; u <= h; ++u) {
      auto at = [&](int du, int dv) { return s[static_cast<std::size_t>((v + dv + h + 1) * w + u + du + h + 1)]; };
      const float gx = 0.5f * (at(1, 0) - at(-1, 0)), gy = 0.5f * (at(0, 1) - at(0, -1));
      const auto fu = static_cast<float>(u), fv = static_cast<float>(v);
      const int k = (v + h) * n + u + h;
      values(k) = at(0, 0);
      // ∂W/∂p of W(x; p) = [(1 + p1) u + p3 v + p5; p2 u + (1 + p4) v + p6] at p = 0.
      sd.col(k) << gx * fu, gy * fu, gx * fv, gy * fv, gx, gy;
    }
  }
  const double mean = values.cast<double>().mean();
  const Eigen::VectorXf centred = (values.cast<double>().array() - mean).matrix().cast<float>();
  const float norm = centred.norm();
  const Eigen::Matrix<double, 6, 6> H = sd.cast<double>() * sd.cast<double>().transpose();
  // An untextured or edge-only patch does not fix all six parameters.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eig(H, Eigen::EigenvaluesOnly);
  const double lmin = eig.eigenvalues()(0), lmax = eig.eigenvalues()(5);
  if (!(lmax > 0.0) || !(lmin > 1e-6 * lmax) || !(norm > 0.0f)) return false;
  centred_ = centred;
  sd_ = sd;
  sdTemplate_ = sd_ * centred_;
  norm_ = norm;
  hessianInverse_ = H.inverse().cast<float>();
  translationHessianInverse_ = H.bottomRightCorner<2, 2>().inverse().cast<float>();
  half_ = h;
  return true;
}

PatchAlignResult AffinePatch::align(const cv::Mat& image, AffineWarp& W, const PatchAlignParams& p) const {
  PatchAlignResult res;
  if (empty() || image.empty() || image.type() != CV_8UC1) return res;
  const int h = half_, n = 2 * h + 1;
  const auto fh = static_cast<float>(h);
  // Per-thread buffer of the warped patch (no allocation per call).
  thread_local Eigen::VectorXf I;
  I.resize(centred_.size());
  const float lo = 1.0f - p.maxShapeChange, hi = 1.0f / lo;
  // Translation only until the centre is within a tenth of a pixel (at most half of the
  // iterations): far from the optimum the six-parameter step couples shape and shift badly.
  bool shape = false;
  int translationSteps = 0;
  // translationFallback: the warp at the switch to the shape stage and its correlation.
  std::optional<AffineWarp> translated;
  float translatedCorrelation = 0.0f;
  const auto fallback = [&]() -> PatchAlignResult {
    if (!p.translationFallback || !translated) return res;
    W = *translated;
    res.correlation = translatedCorrelation;
    res.ok = translatedCorrelation >= p.minCorrelation;
    return res;
  };
  for (int it = 0; it < p.maxIterations; ++it) {
    res.iterations = it + 1;
    // The warped patch is a parallelogram: inside the image if its corners are.
    for (const float su : {-fh, fh}) {
      for (const float sv : {-fh, fh}) {
        const Eigen::Vector2f q = W.A * Eigen::Vector2f(su, sv) + W.t;
        if (!inside(image, q.x(), q.y())) return fallback();
      }
    }
    const Eigen::Vector2f du = W.A.col(0);
    for (int v = -h; v <= h; ++v) {
      // Row start and step of the warped grid: q(u, v) = A (u, v) + t.
      const Eigen::Vector2f row = W.A * Eigen::Vector2f(-fh, static_cast<float>(v)) + W.t;
      float* out = I.data() + (v + h) * n;
      for (int u = 0; u < n; ++u) {
        out[u] = sample(image, row.x() + du.x() * static_cast<float>(u), row.y() + du.y() * static_cast<float>(u));
      }
    }
    // Centred warped patch; gain and bias that map it onto the template (least squares):
    // gain·(I − Ī) − (T − T̄) is the error, so the steepest-descent product is
    // gain·(SD·(I − Ī)) − SD·(T − T̄).
    const float meanI = I.sum() / static_cast<float>(I.size());
    I.array() -= meanI;
    const double sII = I.squaredNorm(), sIT = I.dot(centred_);
    if (!(sII > 0.0)) return fallback();
    res.correlation = static_cast<float>(sIT / (std::sqrt(sII) * static_cast<double>(norm_)));
    const auto gain = static_cast<float>(sIT / sII);
    Eigen::Matrix<float, 6, 1> dp = Eigen::Matrix<float, 6, 1>::Zero();
    if (shape) {
      const Eigen::Matrix<float, 6, 1> b = gain * (sd_ * I) - sdTemplate_;
      dp = hessianInverse_ * b;
    } else {
      const Eigen::Vector2f b = gain * (sd_.bottomRows<2>() * I) - sdTemplate_.tail<2>();
      dp.tail<2>() = translationHessianInverse_ * b;
      ++translationSteps;
    }
    // W ← W ∘ W(Δp)⁻¹ (B&M eq. (32)): W(Δp)(x) = ΔA x + Δt, its inverse ΔA⁻¹ (x − Δt).
    Eigen::Matrix2f dA;
    dA << 1.0f + dp(0), dp(2), dp(1), 1.0f + dp(3);
    if (!(std::abs(dA.determinant()) > 1e-3f)) return fallback();
    const Eigen::Matrix2f A = W.A * dA.inverse();
    const Eigen::Vector2f t = W.t - A * dp.tail<2>();
    const float step = (t - W.t).norm();
    const AffineWarp before = W;
    W.A = A;
    W.t = t;
    if (!std::isfinite(step)) return fallback();
    const Eigen::JacobiSVD<Eigen::Matrix2f> svd(W.A);
    if (!(svd.singularValues()(1) >= lo && svd.singularValues()(0) <= hi)) return fallback();
    if (!shape) {
      shape = step < 0.1f || 2 * translationSteps >= p.maxIterations;
      if (shape && step < 0.1f) {
        translated = before;  // converged in translation: the last measured warp
        translatedCorrelation = res.correlation;
      }
      continue;
    }
    if (step < p.epsilon) {
      res.ok = res.correlation >= p.minCorrelation;
      return res;
    }
  }
  return fallback();
}

}  // namespace gvins::vio
