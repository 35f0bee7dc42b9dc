// Private: the end of a frame of the SRI-SWF estimator — re-anchoring of the SLAM features
// anchored at the oldest clone, and marginalization of lost SLAM features and of that clone.
#pragma once

#include <vector>

#include "swf_state.hpp"

namespace gvins::vio::detail {

/// Re-anchors the SLAM features anchored at `old_anchor` to the newest clone: with
/// reanchor_sigma 0 an exact change of variables of each feature block in place
/// (SriFilter::substitute), else a Propagation with that noise into new blocks, then the old
/// blocks are marginalized. Features that cannot be re-anchored (behind the new anchor's
/// camera) leave the SLAM set and are returned for marginalization.
template <typename Scalar>
std::vector<sri::BlockId> reanchorSlamFeatures(SwfState<Scalar>& s, sri::BlockId old_anchor);

/// Step 3 of a frame: marginalizes `lost_slam` and, when `dropping`, the oldest clone (after
/// re-anchoring its SLAM features; its first estimate, motion and observations are dropped).
template <typename Scalar>
void marginalizeWindow(SwfState<Scalar>& s, std::vector<sri::BlockId> lost_slam, bool dropping);

}  // namespace gvins::vio::detail
