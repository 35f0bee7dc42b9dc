#include "gvins/gnss/kml_writer.hpp"

#include <cstdio>
#include <ostream>

#include "gvins/base/constants.hpp"

namespace gvins {

std::string xmlEscape(std::string_view text) {
  std::string s;
  s.reserve(text.size());
  for (const char c : text) {
    switch (c) {
      case '&': s += "&amp;"; break;
      case '<': s += "&lt;"; break;
      case '>': s += "&gt;"; break;
      case '"': s += "&quot;"; break;
      case '\'': s += "&apos;"; break;
      default: s += c;
    }
  }
  return s;
}

void writeKmlTrack(std::ostream& o, const std::vector<Geodetic>& points, std::string_view name) {
  o << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<kml xmlns=\"http://www.opengis.net/kml/2.2\">\n<Document>\n"
    << "<name>" << xmlEscape(name) << "</name>\n"
    << "<Style id=\"track\"><LineStyle><color>ff0000ff</color><width>2</width></LineStyle></Style>\n"
    << "<Placemark><name>antenna track</name><styleUrl>#track</styleUrl><LineString><altitudeMode>absolute</altitudeMode><coordinates>\n";
  char b[96];
  for (const Geodetic& g : points) {
    std::snprintf(b, sizeof b, "%.9f,%.9f,%.3f\n", g.lon * constants::kRadToDeg, g.lat * constants::kRadToDeg, g.height);
    o << b;
  }
  o << "</coordinates></LineString></Placemark>\n</Document>\n</kml>\n";
}

}  // namespace gvins
