// The gvins-rtcm subcommands.
#pragma once

#include <string>
#include <vector>

namespace gvins::rtcm_app {

int runInfo(const std::vector<std::string>& args);
int runToRinex(const std::vector<std::string>& args);
int runNtrip(const std::vector<std::string>& args);
int runFromProducts(const std::vector<std::string>& args);

}  // namespace gvins::rtcm_app
