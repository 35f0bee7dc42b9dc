// Climatological surface meteorology for tropospheric delay models, from latitude, day of year
// and height, after the tropospheric model of RTCA DO-229 (WAAS MOPS), appendix A.4.2.4.
#pragma once

#include "gvins/gnss/saastamoinen.hpp"

namespace gvins {

/// Pressure (hPa), temperature (K) and water-vapour pressure (hPa) at `height` (m above sea
/// level; ellipsoidal heights are close enough) for a geodetic latitude (rad) and day of year.
/// Sea-level averages and seasonal amplitudes are tabulated at 15, 30, 45, 60, 75 degrees
/// (DO-229 table A-2), interpolated linearly in |latitude|, with the annual term
/// xi = xi0 - dxi cos(2 pi (doy - doyMin) / 365.25), doyMin = 28 in the north and 211 in the
/// south; pressure and water vapour are reduced to the height with the tabulated temperature
/// lapse rate beta and water-vapour lapse rate lambda.
SurfaceMeteo climatologicalMeteo(double latitude, double height, double dayOfYear);

}  // namespace gvins
