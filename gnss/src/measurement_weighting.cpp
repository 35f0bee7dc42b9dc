#include "gvins/gnss/measurement_weighting.hpp"

#include <algorithm>
#include <cmath>

namespace gvins {

namespace {
double shape(const MeasurementWeighting& w, double a2, double b2, double elevation, double snr) {
  const double s = std::max(std::sin(elevation), 0.05);  // elevations below ~3 deg saturate
  const double elev = b2 / (s * s);
  switch (w.scheme) {
    case WeightingScheme::Elevation: return a2 + elev;
    case WeightingScheme::Snr:
      if (snr <= 0.0) return a2 + elev;
      return (a2 + b2) * std::pow(10.0, (w.snrReference - snr) / 10.0);
    case WeightingScheme::ElevationSnr:
      if (snr <= 0.0) return a2 + elev;
      return a2 * std::pow(10.0, (w.snrReference - snr) / 10.0) + elev;
  }
  return a2 + elev;
}
}  // namespace

MeasurementWeighting MeasurementWeighting::evenSplit(WeightingScheme scheme, double sigma) {
  MeasurementWeighting w;
  w.scheme = scheme;
  w.a = w.b = sigma * std::sqrt(0.5);
  w.systemFactor.fill(1.0);
  return w;
}

double MeasurementWeighting::codeVariance(System sys, double elevation, double snr) const {
  const double f = systemFactor[systemIndex(sys)];
  return f * f * shape(*this, a * a, b * b, elevation, snr);
}

double MeasurementWeighting::combinationCodeVariance(System sys, double elevation, double a1, double snr1, double a2,
                                                     double snr2) const {
  return a1 * a1 * codeVariance(sys, elevation, snr1) + a2 * a2 * codeVariance(sys, elevation, snr2);
}

double MeasurementWeighting::dopplerVariance(System sys, double elevation, double snr) const {
  // Same shape as the code model, scaled so that sqrt(a^2 + b^2) corresponds to dopplerSigma.
  const double norm = a * a + b * b;
  const double f = systemFactor[systemIndex(sys)];
  const double k = norm > 0.0 ? dopplerSigma * dopplerSigma / norm : 0.0;
  return f * f * k * shape(*this, a * a, b * b, elevation, snr);
}

}  // namespace gvins
