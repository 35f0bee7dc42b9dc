// The gvins-ubx subcommands.
#pragma once

#include <string>
#include <vector>

namespace gvins::ubx_app {

int runInfo(const std::vector<std::string>& args);
int runToRinex(const std::vector<std::string>& args);

}  // namespace gvins::ubx_app
