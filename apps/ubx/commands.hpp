// The gvins-ubx subcommands; each reads its options and operands from `cl` (after the command).
#pragma once

#include "gvins/base/command_line.hpp"

namespace gvins::ubx_app {

int runInfo(CommandLine& cl);
int runToRinex(CommandLine& cl);
int runToPos(CommandLine& cl);

}  // namespace gvins::ubx_app
