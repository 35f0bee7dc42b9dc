// Broadcast ephemerides sampled into SP3 form: positions of the records' antenna phase centres and
// their clocks without the periodic relativistic term (the SP3 convention), for tools that read
// SP3 only, or to compare an SP3 reader's interpolation against the broadcast orbit.
#pragma once

#include <vector>

#include "gvins/base/gnss_time.hpp"
#include "gvins/base/satellite.hpp"
#include "gvins/ephemeris/ephemeris_store.hpp"
#include "gvins/ephemeris/sp3.hpp"

namespace gvins {

/// Epochs start, start + interval, ... up to end; every satellite of `sats` (empty: every
/// satellite of the store) at every epoch, a missing record where the store has no usable
/// record. Each epoch uses the record the store selects then, so where records change (GLONASS
/// every 30 min, Galileo every 10 min) the samples carry the record-to-record jumps (mm to dm).
/// Throws std::invalid_argument for interval <= 0 or end < start.
Sp3Data broadcastSp3(const EphemerisStore& nav, const GpsTime& start, const GpsTime& end, double interval,
                     std::vector<SatId> sats = {});

}  // namespace gvins
