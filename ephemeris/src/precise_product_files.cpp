#include "gvins/ephemeris/precise_product_files.hpp"

#include <cctype>
#include <filesystem>

#include "gvins/ephemeris/rinex_clock.hpp"
#include "gvins/ephemeris/sp3.hpp"

namespace gvins {

PreciseFileKind preciseFileKind(std::string_view path) {
  std::string lower = std::filesystem::path(path).filename().string();
  for (char& ch : lower) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  if (lower.size() > 3 && lower.ends_with(".gz")) lower.resize(lower.size() - 3);
  if (lower.ends_with(".sp3")) return PreciseFileKind::kOrbit;
  if (lower.ends_with(".clk") || lower.ends_with(".clk_30s")) return PreciseFileKind::kClock;
  if (lower.ends_with(".atx")) return PreciseFileKind::kAntenna;
  if (lower.ends_with(".bia") || lower.ends_with(".bsx")) return PreciseFileKind::kBias;
  return PreciseFileKind::kOther;
}

bool PreciseProductFiles::add(const std::string& path) {
  switch (preciseFileKind(path)) {
    case PreciseFileKind::kOrbit: orbits.push_back(path); return true;
    case PreciseFileKind::kClock: clocks.push_back(path); return true;
    case PreciseFileKind::kAntenna: antennas.push_back(path); return true;
    case PreciseFileKind::kBias: biases.push_back(path); return true;
    case PreciseFileKind::kOther: return false;
  }
  return false;
}

std::shared_ptr<PreciseEphemeris> readPreciseProducts(const std::vector<std::string>& orbitFiles,
                                                      const std::vector<std::string>& clockFiles) {
  auto precise = std::make_shared<PreciseEphemeris>();
  for (const std::string& f : orbitFiles) precise->add(readSp3(f));
  for (const std::string& f : clockFiles) precise->add(readRinexClock(f));
  return precise;
}

namespace {

/// Reads every file and appends its items (`items`) to the first file's data (whose header wins).
template <typename Data, typename Item>
std::shared_ptr<Data> readAndMerge(const std::vector<std::string>& files, Data (*read)(const std::string&),
                                   std::vector<Item> Data::*items) {
  auto out = std::make_shared<Data>();
  for (const std::string& f : files) {
    Data d = read(f);
    if ((*out.*items).empty()) {
      *out = std::move(d);
      continue;
    }
    for (Item& x : d.*items) (*out.*items).push_back(std::move(x));
  }
  return out;
}

}  // namespace

std::shared_ptr<AntexData> readAntennaFiles(const std::vector<std::string>& files) {
  return readAndMerge(files, &readAntex, &AntexData::antennas);
}

std::shared_ptr<BiasSinexData> readCodeBiasFiles(const std::vector<std::string>& files) {
  return readAndMerge(files, &readBiasSinex, &BiasSinexData::entries);
}

}  // namespace gvins
