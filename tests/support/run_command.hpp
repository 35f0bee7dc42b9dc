// Runs a shell command for the command-line tool tests: its standard output (and whatever the
// command redirects there) and its exit status.
#pragma once

#include <cstdio>
#include <string>
#include <utility>

#include <sys/wait.h>

namespace gvins::test {

/// {output, exit status} of `cmd` run by /bin/sh; status -1 when it did not exit normally or
/// could not be started.
inline std::pair<std::string, int> runCommand(const std::string& cmd) {
  std::FILE* p = ::popen(cmd.c_str(), "r");
  if (!p) return {std::string(), -1};
  std::string out;
  char buf[4096];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  const int status = ::pclose(p);
  return {out, WIFEXITED(status) ? WEXITSTATUS(status) : -1};
}

}  // namespace gvins::test
