// A usage error as the CLI must give it: exit 1 and exactly one line on stderr.
#pragma once
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "tests/support/cli_run.h"

namespace gibake::test {

// Runs `args`, expects exit 1 and one stderr line, and returns that line ("" when there is none).
inline std::string usage_error_line(const std::string& args) {
  const CliResult r = run_gibake_cli(args);
  EXPECT_EQ(r.exit_code, 1) << args << "\n" << r.err;
  const std::vector<std::string> lines = split_lines(r.err);
  EXPECT_EQ(lines.size(), 1u) << args << "\n" << r.err;
  return lines.empty() ? std::string() : lines[0];
}

}  // namespace gibake::test
