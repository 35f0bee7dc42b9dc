#include "gvins/vio/imu_state.hpp"

#include "gvins/vio/so3.hpp"

namespace gvins::vio {

void boxPlus(ImuState& s, const Vector15d& d) {
  s.R_WI = s.R_WI * so3::exp(d.segment<3>(ImuErr::kTheta));
  s.p_WI += d.segment<3>(ImuErr::kPos);
  s.v_WI += d.segment<3>(ImuErr::kVel);
  s.bg += d.segment<3>(ImuErr::kBg);
  s.ba += d.segment<3>(ImuErr::kBa);
}

Vector15d boxMinus(const ImuState& truth, const ImuState& est) {
  Vector15d d;
  d.segment<3>(ImuErr::kTheta) = so3::log(est.R_WI.transpose() * truth.R_WI);
  d.segment<3>(ImuErr::kPos) = truth.p_WI - est.p_WI;
  d.segment<3>(ImuErr::kVel) = truth.v_WI - est.v_WI;
  d.segment<3>(ImuErr::kBg) = truth.bg - est.bg;
  d.segment<3>(ImuErr::kBa) = truth.ba - est.ba;
  return d;
}

}  // namespace gvins::vio
