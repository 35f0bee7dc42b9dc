// Broadcast ionosphere model parameters and GNSS-to-GNSS/UTC time corrections carried in
// navigation headers and messages.
#pragma once

#include <array>
#include <optional>

#include "gvins/base/gnss_time.hpp"
#include "gvins/base/satellite.hpp"

namespace gvins {

/// Klobuchar coefficients (IS-GPS-200 20.3.3.5.2.5): alpha in s, s/semicircle, ...; beta in s,
/// s/semicircle, ... . BeiDou broadcasts the same form (BDS-SIS-ICD B1I 5.2.4.7).
struct KlobucharParameters {
  std::array<double, 4> alpha{};
  std::array<double, 4> beta{};
};

/// Galileo NeQuick-G effective ionisation level coefficients ai0 (sfu), ai1 (sfu/deg),
/// ai2 (sfu/deg^2) (Galileo OS SIS ICD 5.1.6).
struct NeQuickParameters {
  std::array<double, 3> ai{};
};

/// A time-system correction "A0 + A1 (t - tref)" from a RINEX header line
/// (GPUT, GAUT, GAGP, BDUT, GLUT, GLGP, QZUT, QZGP, ...).
struct TimeSystemCorrection {
  char type[5] = {0, 0, 0, 0, 0};  ///< four-letter RINEX code, e.g. "GAGP"
  double a0 = 0.0;                 ///< s
  double a1 = 0.0;                 ///< s/s
  double referenceTow = 0.0;       ///< s of week
  int referenceWeek = 0;           ///< week number as given in the file
  double a2 = 0.0;                 ///< s/s^2 (RINEX 4 STO records; 0 in RINEX 2/3 headers)
};

/// Ionosphere parameters per source.
struct IonosphereParameters {
  std::optional<KlobucharParameters> gps;
  std::optional<KlobucharParameters> qzss;
  std::optional<KlobucharParameters> beidou;
  std::optional<NeQuickParameters> galileo;
};

}  // namespace gvins
