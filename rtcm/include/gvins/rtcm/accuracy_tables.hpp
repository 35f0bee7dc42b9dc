// Conversions between broadcast accuracy indices and metres, shared by decoder and encoder.
#pragma once

namespace gvins::rtcm {

/// GPS/QZSS URA index N (IS-GPS-200 20.3.3.3.1.3) and BeiDou URAI (BDS-SIS-ICD B1I 5.2.4.5) to
/// the nominal value written to RINEX (RINEX 3.04 table A6: 2^(1+N/2) rounded to 0.1 m for N <= 6,
/// 2^(N-2) for 6 < N < 15, 8192 = no accuracy prediction for N = 15).
double uraMetres(int index);
/// Smallest index whose nominal value is not below `metres`.
int uraIndex(double metres);

/// Galileo SISA index (Galileo OS SIS ICD 2.1, 5.1.12) to metres: 0-49 step 1 cm, 50-74 from
/// 0.5 m step 2 cm, 75-99 from 1 m step 4 cm, 100-125 from 2 m step 16 cm; 126-254 spare and
/// 255 "no accuracy prediction" give -1.
double sisaMetres(int index);
/// Inverse (nearest index; 255 for a negative value or one beyond 6 m).
int sisaIndex(double metres);

/// GLONASS FT (GLONASS ICD 5.1, table 4.4) to metres; 0 for the unused value 15.
double glonassFtMetres(int ft);
/// Inverse: smallest FT whose value is not below `metres`; 15 for 0 (unknown).
int glonassFtIndex(double metres);

}  // namespace gvins::rtcm
