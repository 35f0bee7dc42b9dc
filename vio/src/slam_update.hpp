// Private: the SLAM features of the SRI-SWF estimator — their re-observation update and the
// creation of new ones from window-long tracks.
#pragma once

#include <cstdint>
#include <vector>

#include "swf_state.hpp"

namespace gvins::vio::detail {

/// A window-long track chosen to become a SLAM feature: its inverse depth in camera 0 of the
/// newest clone and the three rows that fix it (made by MsckfUpdater with the MSCKF rows).
template <typename Scalar>
struct NewSlamFeature {
  std::uint64_t id = 0;
  Eigen::Vector3d f0 = Eigen::Vector3d::Zero();  // inverse depth in camera 0 of the newest clone
  AnchoredPoint apj;                              // its world point and Jacobians at the anchor's first estimate
  sri::Measurement<Scalar> top;  // Q₁ᵀ[H_f H_x r]: feature position (nuisance, triangular), H_x, residual
};

template <typename Scalar>
class SlamUpdater {
 public:
  using Meas = sri::Measurement<Scalar>;

  /// Step 1 of a frame: the rows of every SLAM feature observed in `frame` (newest clone),
  /// applied jointly if their joint χ² passes, else each feature gated on its own; features not
  /// observed, behind the camera or rejected are removed from the SLAM set and returned (their
  /// blocks, for marginalization). Counts gated and rejected features in `res`; sets
  /// res.updated when rows were applied.
  std::vector<sri::BlockId> updateReobserved(SwfState<Scalar>& s, const FeatureFrame& frame, FrameResult& res);

  /// Step 2c: a state block for each new feature (anchored at the newest clone, no prior, in
  /// front of the clones) and its three rows, by the chain rule δp_W = J_f δf + J_a δx_anchor +
  /// J_e δext₀ at the Jacobians' linearisation point.
  void initialize(SwfState<Scalar>& s, const std::vector<NewSlamFeature<Scalar>>& fresh, FrameResult& res);

  /// Rows of a SLAM feature for observations from the listed clones (anchored inverse depth;
  /// Jacobians at first estimates, residuals at the current ones), triangularized in the
  /// feature's columns. False when the point is not in front of an observing camera.
  bool rows(SwfState<Scalar>& s, const typename SwfState<Scalar>::Slam& f,
            const std::vector<typename SwfState<Scalar>::Obs>& obs, Meas& m);

 private:
  // Speculative joint update: update() only changes R and r, so only they are saved (a copy of
  // the whole filter also copied its capacity-sized buffers and workspaces).
  Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> backup_R_;
  Eigen::Matrix<Scalar, Eigen::Dynamic, 1> backup_r_;
};

extern template class SlamUpdater<float>;
extern template class SlamUpdater<double>;

}  // namespace gvins::vio::detail
