#include "gvins/gnss/solution_outputs.hpp"

#include "gvins/gnss/kml_writer.hpp"

namespace gvins {

SolutionOutputs::SolutionOutputs(const std::string& nmeaPath, const std::string& kmlPath, std::string kmlName,
                                 NmeaOptions nmea)
    : kmlName_(std::move(kmlName)) {
  if (!nmeaPath.empty()) {
    nmeaFile_.emplace(nmeaPath);
    nmea_ = std::make_unique<NmeaWriter>(nmeaFile_->stream(), std::move(nmea));
  }
  if (!kmlPath.empty()) kml_.emplace(kmlPath);
}

void SolutionOutputs::add(const PositionSolution& s, const NmeaExtras& extras) {
  if (nmea_) nmea_->write(s, extras);
  if (kml_ && s.quality != SolutionQuality::None && s.position.norm() > 1.0) track_.push_back(ecefToGeodetic(s.position));
}

void SolutionOutputs::finish(bool success) {
  if (kml_ && success) writeKmlTrack(kml_->stream(), track_, kmlName_);
  if (kml_) kml_->finish(success);
  if (nmeaFile_) nmeaFile_->finish(success);
  kml_.reset();
  nmeaFile_.reset();
  nmea_.reset();
}

}  // namespace gvins
