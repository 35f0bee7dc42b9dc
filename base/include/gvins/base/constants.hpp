// Physical and per-system geodetic constants, each cited from its interface control document.
#pragma once

#include "gvins/base/satellite.hpp"

namespace gvins::constants {

/// Speed of light in vacuum, m/s (exact; used by all GNSS ICDs).
inline constexpr double kSpeedOfLight = 299792458.0;

// GPS (IS-GPS-200N, 20.3.3.4.3.3): WGS 84 values used in the user algorithm.
inline constexpr double kGpsGm = 3.986005e14;            // m^3/s^2
inline constexpr double kGpsOmegaE = 7.2921151467e-5;    // rad/s
/// Relativistic clock correction constant F = -2 sqrt(mu)/c^2 (IS-GPS-200N 20.3.3.3.3.1).
inline constexpr double kGpsF = -4.442807633e-10;        // s/m^(1/2)

// Galileo (OS SIS ICD 2.1, 5.1.1 and table 59).
inline constexpr double kGalileoGm = 3.986004418e14;
inline constexpr double kGalileoOmegaE = 7.2921151467e-5;
inline constexpr double kGalileoF = -4.442807309e-10;

// BeiDou, CGCS2000 (BDS-SIS-ICD-B1I 3.0, 3.2).
inline constexpr double kBeiDouGm = 3.986004418e14;
inline constexpr double kBeiDouOmegaE = 7.2921150e-5;
inline constexpr double kBeiDouF = -4.442807309e-10;

// GLONASS, PZ-90.11 (GLONASS ICD ed. 5.1, table 3.2 and appendix 3.1.2).
inline constexpr double kGlonassGm = 3.9860044e14;
inline constexpr double kGlonassOmegaE = 7.292115e-5;
inline constexpr double kGlonassAe = 6378136.0;          // semi-major axis, m
inline constexpr double kGlonassJ2 = 1.0826257e-3;       // second zonal harmonic (C20 = -J2)

// QZSS uses the GPS constants (IS-QZSS-PNT-004, 5.1.2.1).

/// WGS 84 ellipsoid (NIMA TR8350.2): semi-major axis and flattening.
inline constexpr double kWgs84A = 6378137.0;
inline constexpr double kWgs84F = 1.0 / 298.257223563;
inline constexpr double kWgs84E2 = kWgs84F * (2.0 - kWgs84F);
/// WGS 84 Earth rotation rate (also used for Sagnac corrections), rad/s.
inline constexpr double kWgs84OmegaE = 7.2921151467e-5;

/// Earth gravitational constant and rotation rate used for a system's orbit computation.
constexpr double gravitationalConstant(System s) {
  switch (s) {
    case System::Galileo: return kGalileoGm;
    case System::BeiDou: return kBeiDouGm;
    case System::Glonass: return kGlonassGm;
    default: return kGpsGm;
  }
}
constexpr double earthRotationRate(System s) {
  switch (s) {
    case System::Galileo: return kGalileoOmegaE;
    case System::BeiDou: return kBeiDouOmegaE;
    case System::Glonass: return kGlonassOmegaE;
    default: return kGpsOmegaE;
  }
}

inline constexpr double kPi = 3.1415926535898;  // value prescribed by IS-GPS-200 for orbit code
inline constexpr double kDegToRad = 3.14159265358979323846 / 180.0;
inline constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;

}  // namespace gvins::constants
