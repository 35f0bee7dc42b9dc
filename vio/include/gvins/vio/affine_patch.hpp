// A feature's appearance at detection (its template patch) and its alignment with a later image
// under an affine warp with gain and bias: the inverse compositional Lucas-Kanade algorithm
// (Baker & Matthews, "Lucas-Kanade 20 Years On: A Unifying Framework", IJCV 56(3), 2004, §3.2,
// affine warp of eq. (1)), with the photometric gain and bias fitted in closed form to the warped
// patch before every step.
//
// Why: frame-to-frame KLT with a translation-only window, chained along a track whose patch
// rotates and changes scale (a turning camera), drifts off the scene point it started on by a
// fraction of a pixel per image, always the same way (docs/vio_frontend.md, test
// RenderedDrift.*). Aligning every image with the template of the detection image instead has
// no chain: the error does not grow with the track's age.
//
// Bilinear interpolation smooths by an amount that depends on the sub-pixel phase; on sharp
// images that difference between the template (often taken at whole pixels) and the warped patch
// biases the shape, and through it the centre, by several hundredths of a pixel. Both images
// should therefore be smoothed first (a Gaussian of σ ≈ 1 px; FeatureTracker does).
#pragma once

#include <vector>

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>
#include <opencv2/core/types.hpp>

namespace gvins::vio {

/// Image position of the template's centre and the local shape: pixel (u, v) of the template
/// (offsets from its centre) is at `A (u, v)ᵀ + t` in the image.
struct AffineWarp {
  Eigen::Matrix2f A = Eigen::Matrix2f::Identity();
  Eigen::Vector2f t = Eigen::Vector2f::Zero();
};

struct PatchAlignParams {
  int halfSize = 7;              ///< template of (2 halfSize + 1)² pixels
  int maxIterations = 10;
  float epsilon = 0.005f;        ///< px: stop once the centre moves less than this
  float minCorrelation = 0.9f;   ///< normalized cross-correlation of the aligned patch, [−1, 1]
  float maxShapeChange = 0.5f;   ///< singular values of A must stay in [1 − c, 1/(1 − c)]
  /// When the six-parameter (shape) stage fails after the translation stage converged (shape
  /// out of bounds, no convergence, singular step: typical of patches with texture in one
  /// direction only, e.g. a close, magnified ground), return the translation-stage warp instead,
  /// accepted if its correlation reaches minCorrelation.
  bool translationFallback = false;
};

struct PatchAlignResult {
  bool ok = false;
  int iterations = 0;
  float correlation = 0.0f;
};

class AffinePatch {
 public:
  AffinePatch() = default;
  /// Samples the template centred at `centre` from the 8-bit gray `image`. False (and an empty
  /// template) if the patch and its gradient border are not inside the image.
  bool extract(const cv::Mat& image, const cv::Point2f& centre, const PatchAlignParams& params);
  bool empty() const { return centred_.size() == 0; }

  /// Refines `warp` (initial guess in, result out) so that the image under the warp matches the
  /// template. Fails (result.ok false, warp unspecified) when the patch leaves the image, the
  /// normal equations are singular, the shape degenerates, the iteration does not converge or the
  /// aligned patch correlates less than params.minCorrelation with the template.
  PatchAlignResult align(const cv::Mat& image, AffineWarp& warp, const PatchAlignParams& params) const;

 private:
  int half_ = 0;
  // Template intensities minus their mean, row-major (2h+1)² (empty: no template).
  Eigen::VectorXf centred_;
  // Steepest-descent images ∇T ∂W/∂p, one row per parameter (rows are contiguous, so the
  // per-iteration products with the warped patch are vectorised dot products).
  Eigen::Matrix<float, 6, Eigen::Dynamic, Eigen::RowMajor> sd_;
  Eigen::Matrix<float, 6, 1> sdTemplate_;    // sd_ · centred_
  Eigen::Matrix<float, 6, 6> hessianInverse_;
  Eigen::Matrix2f translationHessianInverse_;
  float norm_ = 0.0f;                        // sqrt(Σ (T − mean)²)
};

}  // namespace gvins::vio
