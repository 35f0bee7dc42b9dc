// Broadcast single-frequency ionosphere models: GPS/QZSS Klobuchar and the BeiDou variant.
#pragma once

#include "gvins/base/geodetic.hpp"
#include "gvins/base/gnss_time.hpp"
#include "gvins/base/local_frame.hpp"
#include "gvins/base/satellite.hpp"
#include "gvins/ephemeris/ionosphere_parameters.hpp"

namespace gvins {

/// GPS Klobuchar model (IS-GPS-200N 20.3.3.5.2.5, figure 20-4): slant ionospheric group delay on
/// L1 in metres for a receiver (geodetic), satellite azimuth/elevation and GPS time.
double klobucharDelayL1(const KlobucharParameters& p, const Geodetic& receiver, const AzEl& azel,
                        const GpsTime& t);
/// The same with its obliquity factor klobucharObliquity(azel.elevation) given, for callers that
/// use the factor themselves (the result is the same).
double klobucharDelayL1(const KlobucharParameters& p, const Geodetic& receiver, const AzEl& azel,
                        const GpsTime& t, double obliquity);
/// Obliquity factor of the broadcast model, F = 1 + 16 (0.53 - E)^3 with E the elevation in
/// semicircles (IS-GPS-200N figure 20-4).
double klobucharObliquity(double elevation);

/// BeiDou Klobuchar variant (BDS-SIS-ICD-B1I 3.0, 5.2.4.7): single-layer model at 375 km with
/// geographic ionospheric pierce point, BDT local time, the 72000..172800 s period clamp; slant
/// delay on B1I (1561.098 MHz) in metres.
double beidouKlobucharDelayB1I(const KlobucharParameters& p, const Geodetic& receiver, const AzEl& azel,
                               const GpsTime& t);

/// Scale factor from a delay on a reference frequency to another: (f_ref / f)^2 (first-order
/// ionospheric group delay is proportional to 1/f^2).
double ionosphereFrequencyScale(double referenceFrequency, double frequency);

}  // namespace gvins
