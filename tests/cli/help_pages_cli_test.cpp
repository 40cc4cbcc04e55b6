// `--help` and docs/cli/<command>.md cannot drift apart: every option `gibake <command> --help`
// prints is on the command's page under the same heading, with the same default (the help prints
// it from the args struct), and every option the page lists exists. The help itself is a reference
// card: lines shorter than 100 characters, one line an option, no CLI11 type hints, and the
// commands' one-line descriptions in one style.
#include <gtest/gtest.h>

#include <map>
#include <regex>
#include <string>
#include <vector>

#include "tests/support/cli_run.h"

namespace {

using namespace gibake::test;  // run_gibake_cli, split_lines, read_text_file

const char* const kCommands[] = {"bake", "inspect", "info", "verify", "export", "preview", "merge", "sample"};

struct Entry {
  std::string group, def;  // def: the printed default, "" when none is printed
  bool has_default = false;
};

// The options of one command's --help (the long name, or the short one when it has none), by
// heading. Positionals ("Arguments") and the help flag ("Help") are not options of the page.
std::map<std::string, Entry> help_options(const std::string& help, std::vector<std::string>& groups) {
  std::map<std::string, Entry> out;
  static const std::regex heading(R"(^([A-Z][^:]*):$)"), option(R"(^  (-\S+)( \S+)?  +(.*)$)"),
      flag_only(R"(^  (-\S+)$)"), def(R"( \[default: ([^\]]*)\]$)");
  std::string group;
  for (const std::string& line : split_lines(help)) {
    std::smatch m;
    if (std::regex_match(line, m, heading)) {
      group = m[1];
      if (group != "Arguments" && group != "Help" && group != "Usage") groups.push_back(group);
      continue;
    }
    if (group.empty() || group == "Arguments" || group == "Help") continue;
    std::string names, what;
    if (std::regex_match(line, m, option)) names = m[1], what = m[3];
    else if (std::regex_match(line, m, flag_only)) names = m[1];
    else continue;
    const size_t dashes = names.find("--");
    const std::string name = dashes == std::string::npos ? names : names.substr(dashes, names.find(',', dashes) - dashes);
    Entry e{group, "", false};
    if (std::regex_search(what, m, def)) e.def = m[1], e.has_default = true;
    out[name] = e;
  }
  return out;
}

// A table row's cells, split at the pipes that are not escaped ("\\|" inside a cell).
std::vector<std::string> cells(const std::string& row) {
  std::vector<std::string> out;
  std::string cell;
  for (size_t i = 1; i < row.size(); ++i) {
    if (row[i] == '|' && row[i - 1] != '\\') {
      const size_t a = cell.find_first_not_of(' '), b = cell.find_last_not_of(' ');
      out.push_back(a == std::string::npos ? std::string() : cell.substr(a, b - a + 1));
      cell.clear();
    } else {
      cell += row[i];
    }
  }
  return out;
}

// The page's option tables: "| `--name ARG` | default | what |" rows under "### <heading>" of
// "## Options"; the first `--name` in the first cell names the row.
std::map<std::string, Entry> page_options(const std::string& page, std::vector<std::string>& groups) {
  std::map<std::string, Entry> out;
  static const std::regex long_name(R"(`(--[a-z0-9-]+))"), short_name(R"(`(-[a-z0-9]))");
  bool in_options = false;
  std::string group;
  for (const std::string& line : split_lines(page)) {
    if (line.rfind("## ", 0) == 0) in_options = line == "## Options";
    if (!in_options) continue;
    if (line.rfind("### ", 0) == 0) {
      group = line.substr(4);
      groups.push_back(group);
      continue;
    }
    if (line.rfind("| `-", 0) != 0) continue;
    const std::vector<std::string> c = cells(line);
    if (c.size() < 3) continue;
    std::smatch m;
    if (!std::regex_search(c[0], m, long_name) && !std::regex_search(c[0], m, short_name)) continue;
    std::string def = c[1];
    if (def.size() >= 2 && def.front() == '`' && def.back() == '`') def = def.substr(1, def.size() - 2);
    out[m[1]] = Entry{group, def, true};
  }
  return out;
}

std::string page_of(const std::string& command) {
  return read_text_file(std::string(GIBAKE_SOURCE_DIR) + "/docs/cli/" + command + ".md");
}

TEST(HelpPages, EveryOptionIsOnItsPageWithItsDefault) {
  for (const char* command : kCommands) {
    const CliResult r = run_gibake_cli(std::string(command) + " --help");
    ASSERT_EQ(r.exit_code, 0) << command;
    const std::string page = page_of(command);
    ASSERT_FALSE(page.empty()) << "docs/cli/" << command << ".md is missing";
    std::vector<std::string> help_groups, page_groups;
    const std::map<std::string, Entry> help = help_options(r.out, help_groups);
    const std::map<std::string, Entry> doc = page_options(page, page_groups);
    ASSERT_FALSE(help.empty()) << command << ": no options parsed from\n" << r.out;
    EXPECT_EQ(page_groups, help_groups) << command << ": the page's headings are not the help's";
    for (const auto& [name, h] : help) {
      const auto it = doc.find(name);
      if (it == doc.end()) {
        ADD_FAILURE() << command << " " << name << ": in --help, not in docs/cli/" << command << ".md";
        continue;
      }
      EXPECT_EQ(it->second.group, h.group) << command << " " << name;
      if (h.has_default) EXPECT_EQ(it->second.def, h.def) << command << " " << name << ": the page's default";
      else EXPECT_FALSE(it->second.def.empty()) << command << " " << name << ": say what unset means";
    }
    for (const auto& [name, d] : doc)
      EXPECT_TRUE(help.count(name)) << command << " " << name << ": on the page, not an option of the command";
    for (const char* section : {"## Synopsis", "## Description", "## Options", "## Exit status", "## Examples"})
      EXPECT_NE(page.find(std::string("\n") + section + "\n"), std::string::npos) << command << ": " << section;
  }
}

// Shorter than 100 characters, ASCII, no CLI11 type or validator text, and within an options group
// nothing but one line an option.
void expect_reference_card(const std::string& what, const std::string& help) {
  static const std::regex raw_hint(R"(\b(UINT|INT|FLOAT|TEXT|NUMBER|UINT64)\b)");
  bool in_group = false;
  for (const std::string& line : split_lines(help)) {
    EXPECT_LT(line.size(), 100u) << what << ": " << line;
    for (char c : line) EXPECT_TRUE(static_cast<unsigned char>(c) < 128) << what << ": " << line;
    EXPECT_FALSE(std::regex_search(line, raw_hint)) << what << ": " << line;
    if (line.empty()) {
      in_group = false;
    } else if (line.back() == ':' && line[0] != ' ') {
      in_group = true;
    } else if (in_group) {
      EXPECT_EQ(line.compare(0, 2, "  "), 0) << what << ": " << line;
      EXPECT_FALSE(line.size() > 2 && line[2] == ' ') << what << ": a continuation line: " << line;
    }
  }
}

TEST(HelpPages, EveryHelpLineIsShortAndOneAnOption) {
  expect_reference_card("gibake --help", run_gibake_cli("--help").out);
  for (const char* command : kCommands) {
    const CliResult r = run_gibake_cli(std::string(command) + " --help");
    expect_reference_card(std::string("gibake ") + command + " --help", r.out);
  }
}

// Sentence case, one line, no trailing period: the "Commands:" list of `gibake --help`.
// docs/cli/README.md lists every command with the same description.
TEST(HelpPages, CommandDescriptionsShareOneStyle) {
  const std::string help = run_gibake_cli("--help").out;
  std::map<std::string, std::string> described;
  bool in_commands = false;
  for (const std::string& line : split_lines(help)) {
    static const std::regex item(R"(^  ([a-z]+) +([A-Z].*[^.])$)");
    std::smatch m;
    if (line == "Commands:") {
      in_commands = true;
    } else if (line.empty()) {
      in_commands = false;
    } else if (in_commands) {
      EXPECT_TRUE(std::regex_match(line, m, item)) << line;
      if (!m.empty()) described[m[1]] = m[2];
    }
  }
  EXPECT_EQ(described.size(), std::size(kCommands)) << help;
  std::map<std::string, std::string> index;
  for (const std::string& line : split_lines(page_of("README"))) {
    static const std::regex row(R"(^\| \[([a-z]+)\]\(([a-z]+)\.md\) \| (.*) \|$)");
    std::smatch m;
    if (std::regex_match(line, m, row)) index[m[1]] = m[3];
  }
  EXPECT_EQ(index, described) << "docs/cli/README.md's commands are not gibake --help's";
}

}  // namespace
