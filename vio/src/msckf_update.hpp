// Private: the MSCKF update of the SRI-SWF estimator — which tracks are used, triangulation,
// null-space projection, the χ² gate against the window and the stacked update — and the rows
// of new SLAM features, which join the same stack.
#pragma once

#include <cstdint>
#include <unordered_map>
#include <vector>

#include "slam_update.hpp"
#include "swf_state.hpp"

namespace gvins::vio::detail {

/// The tracks a frame uses: lost tracks (≥ min_track_msckf frames) and, when the oldest clone
/// leaves the window, the tracks observed since it; longest first.
struct FeatureSelection {
  std::vector<std::uint64_t> used;      ///< every candidate (its track restarts or ends after the frame)
  std::vector<std::uint64_t> msckf;     ///< MSCKF features (at most max_msckf_per_frame)
  std::vector<std::uint64_t> slam_new;  ///< window-long tracks that become SLAM features (free slots)
};

/// `observed`: the ids of the frame's features, sorted; `dropping`: the oldest clone
/// (`oldest`) leaves the window after this frame.
template <typename Scalar>
FeatureSelection selectFeatures(const SwfState<Scalar>& s, const std::vector<std::uint64_t>& observed, bool dropping,
                                sri::BlockId oldest);

/// After the updates: used tracks and tracks not observed in the frame are dropped.
template <typename Scalar>
void retireTracks(SwfState<Scalar>& s, const FeatureSelection& sel, const std::vector<std::uint64_t>& observed);

template <typename Scalar>
class MsckfUpdater {
 public:
  using Meas = sri::Measurement<Scalar>;
  using Obs = typename SwfState<Scalar>::Obs;

  /// Step 2b: rows of each MSCKF feature and of each new SLAM feature (triangulated, projected
  /// onto the left null space of the point, gated against the window), stacked, compressed and
  /// applied in one update (sets res.updated, counts features). Valid right after correct().
  /// Returns the new SLAM features that passed, with their three point rows (SlamUpdater::initialize).
  std::vector<NewSlamFeature<Scalar>> update(SwfState<Scalar>& s, const FeatureSelection& sel, FrameResult& res);

  /// Gauss-Newton triangulation (inverse depth in the first observing camera) of a track's
  /// observations; false for too few, ill-conditioned, out-of-depth or short-baseline tracks.
  bool triangulate(SwfState<Scalar>& s, const std::vector<Obs>& obs, Eigen::Vector3d& p_W);

  /// Rows of a feature at world point p_W (nuisance columns) for the listed observations; the
  /// Jacobians at p_J (default p_W; a new SLAM feature's at the point its first-estimate anchor
  /// gives, as SlamUpdater::rows).
  void featureRows(SwfState<Scalar>& s, const std::vector<Obs>& obs, const Eigen::Vector3d& p_W, Meas& m,
                   const Eigen::Vector3d* p_J = nullptr);

 private:
  void windowCovariance(const SwfState<Scalar>& s);
  bool gateWindow(const SwfState<Scalar>& s, const Meas& m);

  /// One observation as triangulation sees it: world-to-camera rotation, camera centre, bearing.
  struct Ray {
    Eigen::Matrix3d R_CW;
    Eigen::Vector3d c;
    Eigen::Vector2d z;
  };
  std::vector<Ray> rays_;  // triangulate()'s buffer
  // The window gate's covariance factor (windowCovariance) and buffers.
  Eigen::MatrixXd Fw_;
  double pw_trace_ = 0.0;
  bool fw_leading_triangular_ = false;
  std::unordered_map<std::uint64_t, int> pw_off_;
  Eigen::MatrixXd gate_H_, gate_G_, gate_S_;
  Eigen::VectorXd gate_z_;
};

extern template class MsckfUpdater<float>;
extern template class MsckfUpdater<double>;

}  // namespace gvins::vio::detail
