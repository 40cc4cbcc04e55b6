// `--help` as the commands' reference card: options under headings that match the code's groups,
// one line an option shorter than kHelpLineLimit, a named argument ("N", "X,Y,Z", "on|off")
// instead of CLI11's type hints, and the default printed from the args struct's initial value
// (`->capture_default_str()`), so that it is written once. docs/cli/<command>.md lists the same
// groups, options and defaults; tests/cli/help_pages_cli_test.cpp holds the two together.
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

namespace gibake::cli {

constexpr size_t kHelpLineLimit = 100;  // every help line is shorter: one line an option on any terminal

// Help for `app` and every subcommand added after this call: the layout above. A subcommand's
// footer is its overview, shown between the usage line and the options.
void use_help_formatter(CLI::App& app);

// Adds options to one subcommand under one help heading; `arg` names what the option takes.
class OptionGroup {
 public:
  OptionGroup(CLI::App& sub, std::string heading) : sub_(sub), heading_(std::move(heading)) {}
  template <class T>
  CLI::Option* option(const std::string& names, T& value, const std::string& arg, const std::string& what) {
    return sub_.add_option(names, value, what)->group(heading_)->option_text(arg);
  }
  CLI::Option* flag(const std::string& names, bool& value, const std::string& what) {
    return sub_.add_flag(names, value, what)->group(heading_);
  }

 private:
  CLI::App& sub_;
  std::string heading_;
};

// The name in `names` closest to `typed`, at most a third of its characters (at least one) edited
// away, or "" (also for names under 3 characters).
std::string closest_name(const std::string& typed, const std::vector<std::string>& names);
// Every long and short option name of `sub` ("--rays", "-o").
std::vector<std::string> option_names(const CLI::App& sub);

}  // namespace gibake::cli
