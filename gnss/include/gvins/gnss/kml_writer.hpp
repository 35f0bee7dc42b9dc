// KML 2.2 (OGC 07-147r2) track of positions: one Placemark with a LineString in absolute
// altitude (ellipsoidal height), coordinates "lon,lat,height" in degrees and metres. Used by
// gvins-spp, gvins-rtk and the fused replay.
#pragma once

#include <iosfwd>
#include <string>
#include <string_view>
#include <vector>

#include "gvins/base/geodetic.hpp"

namespace gvins {

/// Writes a whole KML document with one track named `name` (XML-escaped).
void writeKmlTrack(std::ostream& out, const std::vector<Geodetic>& points, std::string_view name);

/// `text` with &, <, >, " and ' replaced by XML entities.
std::string xmlEscape(std::string_view text);

}  // namespace gvins
