// The gvins-rtcm subcommands. Each parses its own options from argv[2..argc) (CommandLine):
// usage errors print "gvins-rtcm COMMAND: MESSAGE (see --help)" and exit with 2.
#pragma once

#include <string_view>

namespace gvins::rtcm_app {

/// The usage text of gvins-rtcm (all commands).
extern const std::string_view kUsage;

int runInfo(int argc, char** argv);
int runToRinex(int argc, char** argv);
int runNtrip(int argc, char** argv);
int runFromProducts(int argc, char** argv);

}  // namespace gvins::rtcm_app
