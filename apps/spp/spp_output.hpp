// The outputs of a gvins-spp run: the RTKLIB-style .pos file (header from the options, the
// configuration and the input) and the optional NMEA and KML files. All are written under
// temporary names and renamed only when the run succeeds: a failed run leaves no file that looks
// valid (and an older file of that name intact).
#pragma once

#include <string>

#include "gvins/base/atomic_output_file.hpp"
#include "gvins/base/rinex_obs_reader.hpp"
#include "gvins/gnss/base_reader.hpp"
#include "gvins/gnss/pos_writer.hpp"
#include "gvins/gnss/solution_outputs.hpp"
#include "gvins/gnss/spp.hpp"
#include "gvins/gnss/spp_config.hpp"
#include "spp_options.hpp"

namespace gvins::sppapp {

/// The .pos header and columns.
PosWriterOptions posOptions(const SppOptions& args, const SppConfig& cfg, const BaseReader& obs,
                            const RinexObsHeader& hdr);

class SppOutput {
 public:
  /// Opens the files of -o, --nmea and --kml; throws std::runtime_error naming a file that
  /// cannot be created.
  SppOutput(const SppOptions& args, PosWriterOptions options);

  /// Writes a solution (`ps` is sol.toPositionSolution()).
  void write(const SppSolution& sol, const PositionSolution& ps);

  /// Ends the run with `exitCode` (0: success): the files are renamed into place on success,
  /// else discarded. Returns the exit code, 1 when finishing a file failed (message printed).
  int finish(int exitCode);

 private:
  std::string path_;
  OutputTarget target_;
  SolutionOutputs side_;
  PosWriter writer_;
};

}  // namespace gvins::sppapp
