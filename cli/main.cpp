// gibake: argv -> subcommand config -> library call -> exit code.
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <string>
#include <vector>

#include "cli/commands.h"
#include "cli/help.h"
#include "cli/options.h"

#ifndef GIBAKE_VERSION
#define GIBAKE_VERSION "0.0.0"
#endif

namespace {

using gibake::cli::Command;

// The subcommands, in the order `gibake --help` lists them.
const Command* const kCommands[] = {
    &gibake::cli::kBakeCommand,   &gibake::cli::kInspectCommand, &gibake::cli::kInfoCommand,
    &gibake::cli::kVerifyCommand, &gibake::cli::kExportCommand,  &gibake::cli::kPreviewCommand,
    &gibake::cli::kMergeCommand,  &gibake::cli::kSampleCommand};

bool is_subcommand(const std::string& arg) {
  for (const Command* c : kCommands)
    if (arg == c->name) return true;
  return false;
}

// `gibake scene.gltf --ddgi` means `gibake bake scene.gltf --ddgi`.
std::vector<std::string> with_implied_bake(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty()) return args;
  const std::string& first = args.front();
  const bool top_level_flag = first == "-h" || first == "--help" || first == "--version";
  if (!is_subcommand(first) && !top_level_flag) args.insert(args.begin(), "bake");
  return args;
}

// A first word that is neither a command nor a file (`gibake veriy x.gibake`) is a mistyped
// command, not a scene: "" when `first` is a command, a file, or an option.
std::string unknown_command_message(const std::string& first) {
  struct stat st {};
  if (is_subcommand(first) || first.empty() || first[0] == '-' || ::stat(first.c_str(), &st) == 0) return {};
  std::vector<std::string> names;
  for (const Command* c : kCommands) names.push_back(c->name);
  const std::string close = gibake::cli::closest_name(first, names);
  if (!close.empty()) return first + ": unknown command; did you mean '" + close + "'?";
  if (first.find_first_of("./") != std::string::npos) return {};  // a scene path: the import says it is missing
  std::string list;
  for (const std::string& n : names) list += (list.empty() ? "" : ", ") + n;
  return first + ": not a command (" + list + ") nor a scene file";
}

// CLI11's "The following arguments were not expected: 64 --ray" as the option the user meant:
// "--ray: unknown option of 'gibake bake'; did you mean --rays?".
std::string extras_message(CLI::App& app, const CLI::ExtrasError& e) {
  const std::vector<CLI::App*> chosen = app.get_subcommands();
  if (chosen.empty()) return e.what();
  const CLI::App& sub = *chosen.front();
  const std::string command = "'gibake " + sub.get_name() + "'";
  const std::vector<std::string> extra = app.remaining(true);
  for (const std::string& arg : extra) {
    if (arg.size() < 2 || arg[0] != '-' || std::isdigit(static_cast<unsigned char>(arg[1]))) continue;
    const std::string name = arg.substr(0, arg.find('='));
    const std::string close = gibake::cli::closest_name(name, gibake::cli::option_names(sub));
    return name + ": unknown option of " + command +
           (close.empty() ? "; " + command.substr(0, command.size() - 1) + " --help' lists them"
                          : "; did you mean " + close + "?");
  }
  if (!extra.empty()) return extra.front() + ": unexpected argument of " + command;
  return e.what();
}

// Ctrl-C (or SIGTERM, SIGHUP) ends the process as the signal does, exit status 128 + signal, after one line
// saying so. Every output is committed atomically (io/output/bake_atomic.h, whose handler removes
// the temporaries first and then hands the signal on to this one), so none is left half-written.
bool g_stderr_is_terminal = false;
extern "C" void on_stop_signal(int sig) {
  if (g_stderr_is_terminal) (void)!::write(STDERR_FILENO, "\n", 1);  // past a progress bar
  static const char interrupted[] = "gibake: interrupted (SIGINT); no output was left half-written\n";
  static const char terminated[] = "gibake: terminated (SIGTERM); no output was left half-written\n";
  static const char hung_up[] = "gibake: hung up (SIGHUP); no output was left half-written\n";
  if (sig == SIGINT) (void)!::write(STDERR_FILENO, interrupted, sizeof(interrupted) - 1);
  else if (sig == SIGHUP)
    (void)!::write(STDERR_FILENO, hung_up, sizeof(hung_up) - 1);
  else (void)!::write(STDERR_FILENO, terminated, sizeof(terminated) - 1);
  ::signal(sig, SIG_DFL);
  ::raise(sig);
}

// Not where the signal is ignored (`nohup`, a background job of a non-interactive shell).
void say_when_stopped() {
  g_stderr_is_terminal = ::isatty(STDERR_FILENO) != 0;
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) {
    struct sigaction current {};
    if (::sigaction(sig, nullptr, &current) != 0 || current.sa_handler == SIG_IGN) continue;
    struct sigaction action {};
    action.sa_handler = on_stop_signal;
    sigemptyset(&action.sa_mask);
    ::sigaction(sig, &action, nullptr);
  }
  // A file-size limit (`ulimit -f`) would otherwise kill the process mid-write, leaving the atomic
  // writer's temporary behind; ignored, the write fails (EFBIG) as on a full disk: one line, exit 2,
  // the temporary removed.
  ::signal(SIGXFSZ, SIG_IGN);
}

constexpr const char* kExamples = R"(The command 'bake' is implied: 'gibake scene.gltf --ddgi' is 'gibake bake scene.gltf --ddgi'.

Examples:
  gibake scene.gltf --ddgi --out probes.gibake                       bake DDGI probes
  gibake Sponza.gltf --ddgi --sun 0.3,-1,0.2:100000 --out s.gibake   a scene without lights
  gibake scene.gltf --voxels scene.vdb                               voxelize into OpenVDB grids
  gibake scene.gltf --lpv --out lpv.gibake                           light propagation volumes
  gibake inspect scene.gltf                                          what the importer sees
  gibake info probes.gibake                                          what a bake file holds
  gibake verify probes.gibake --scene scene.gltf                     integrity, sanity, staleness
  gibake preview scene.gltf --bake probes.gibake --out view.png      render a view of the bake

'gibake <command> --help' lists a command's options; docs/cli/<command>.md explains each.)";

// A value CLI11 could not convert ("Could not convert: --seed = -1", "Value 1e99 could not be
// converted to UINT") in the user's words: what the option takes (from the type CLI11 converts to)
// and what it got. The shared checks (cli/options.h) catch most values before the conversion; this
// covers every other number option.
std::string expected_message(CLI::App& app, const std::string& name, const std::string& value) {
  std::string kind = "a value of this option's kind";
  for (CLI::App* sub : app.get_subcommands()) {
    const CLI::Option* opt = sub->get_option_no_throw(name);
    if (!opt) continue;
    const std::string type = opt->get_type_name();
    if (type == "UINT") kind = "a whole number, 0 or more";
    else if (type == "INT") kind = "a whole number";
    else if (type == "FLOAT") kind = "a number";
  }
  return name + ": expected " + kind + ", got '" + value + "'";
}

std::string conversion_message(CLI::App& app, const CLI::ConversionError& e) {
  const std::string what = e.what(), head = "Could not convert: ";
  const size_t eq = what.find(" = ");
  if (what.rfind(head, 0) != 0 || eq == std::string::npos) return what;
  return expected_message(app, what.substr(head.size(), eq - head.size()), what.substr(eq + 3));
}

// CLI11's other messages in the user's words: "--out: At Most 1 required but received 2" and
// "--x: Value 1e99 could not be converted to UINT".
std::string parse_message(CLI::App& app, const CLI::ParseError& e) {
  const std::string what = e.what();
  const size_t colon = what.find(": ");
  if (colon == std::string::npos || what.rfind("--", 0) != 0) return what;
  const std::string name = what.substr(0, colon), rest = what.substr(colon + 2);
  const std::string at_most = "At Most 1 required but received ";
  if (rest.rfind(at_most, 0) == 0)
    return name + ": given " + rest.substr(at_most.size()) + " times; it takes one value";
  const std::string value = "Value ", converted = " could not be converted to ", range = " not in range ";
  const size_t c = rest.find(converted), r = rest.find(range), to = rest.find(" to ", r == std::string::npos ? 0 : r);
  if (rest.rfind(value, 0) == 0 && c != std::string::npos)
    return expected_message(app, name, rest.substr(value.size(), c - value.size()));
  if (rest.rfind(value, 0) == 0 && r != std::string::npos && to != std::string::npos) {
    // CLI::Range's bounds, printed with six decimals: as the user would write them, whole numbers
    // in full ("1048576", not "1.04858e+06").
    auto bound = [](const std::string& text) {
      const double v = std::atof(text.c_str());
      char out[32];
      if (v == std::floor(v) && std::fabs(v) < 1e15)
        std::snprintf(out, sizeof out, "%.0f", v);
      else
        std::snprintf(out, sizeof out, "%g", v);
      return std::string(out);
    };
    return name + ": expected a number from " + bound(rest.substr(r + range.size(), to - r - range.size())) + " to " +
           bound(rest.substr(to + 4)) + ", got '" + rest.substr(value.size(), r - value.size()) + "'";
  }
  return what;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace gibake::cli;
  CLI::App app{"gibake: offline global-illumination baker (DDGI probes, LPV and voxel GI from glTF scenes)",
               "gibake"};
  use_help_formatter(app);
  app.set_version_flag("--version", std::string("gibake ") + GIBAKE_VERSION);
  app.get_help_ptr()->description("print this help and exit");
  app.get_version_ptr()->description("print the version and exit");
  app.require_subcommand(1);
  CliState state;
  for (const Command* c : kCommands) {
    CLI::App* sub = app.add_subcommand(c->name);
    sub->group("Commands");
    sub->get_help_ptr()->description("print this help and exit")->group("Help");
    c->add(*sub, state);
    require_finite_numbers(*sub);
    require_paths(*sub);
  }
  app.footer(kExamples);  // after the subcommands, which would inherit it

  std::vector<std::string> args = with_implied_bake(argc, argv);
  if (args.empty()) {  // bare `gibake`: what it does and how to call it
    std::cout << app.help();
    return static_cast<int>(gibake::ExitCode::BadArguments);
  }
  if (argc > 1) {
    if (const std::string wrong = unknown_command_message(argv[1]); !wrong.empty()) {
      std::cerr << "gibake: error: " << wrong << "\n";
      return static_cast<int>(gibake::ExitCode::BadArguments);
    }
  }
  std::reverse(args.begin(), args.end());  // CLI11 consumes a reversed vector
  try {
    app.parse(args);
  } catch (const CLI::ExtrasError& e) {
    std::cerr << "gibake: error: " << extras_message(app, e) << "\n";
    return static_cast<int>(gibake::ExitCode::BadArguments);
  } catch (const CLI::ConversionError& e) {
    std::cerr << "gibake: error: " << conversion_message(app, e) << "\n";
    return static_cast<int>(gibake::ExitCode::BadArguments);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    std::cerr << "gibake: error: " << parse_message(app, e) << "\n";
    return static_cast<int>(gibake::ExitCode::BadArguments);
  }
  if (!state.run) return static_cast<int>(gibake::ExitCode::BadArguments);
  say_when_stopped();
  try {
    return state.run();
  } catch (const std::bad_alloc&) {
    std::cerr << "gibake: error: out of memory\n";
  } catch (const std::exception& e) {
    std::cerr << "gibake: error: " << e.what() << "\n";
  }
  return static_cast<int>(gibake::ExitCode::RuntimeFailure);
}
