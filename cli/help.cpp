#include "cli/help.h"

#include <algorithm>
#include <memory>
#include <sstream>

namespace gibake::cli {

namespace {

constexpr size_t kNameColumn = 30;  // where descriptions start; longer names push theirs right

class HelpFormatter : public CLI::Formatter {
 public:
  std::string make_help(const CLI::App* app, std::string name, CLI::AppFormatMode mode) const override {
    if (mode == CLI::AppFormatMode::Sub) return make_expanded(app);
    std::ostringstream out;
    out << make_description(app) << make_usage(app, name);
    const bool top = app->get_parent() == nullptr;
    if (!top && !app->get_footer().empty()) out << "\n" << app->get_footer() << "\n";
    out << make_positionals(app) << groups(app) << make_subcommands(app, mode);
    if (top) out << "\n" << make_footer(app);
    return out.str();
  }

  std::string make_option(const CLI::Option* opt, bool is_positional) const override {
    std::string left = "  " + make_option_name(opt, is_positional) + (is_positional ? "" : make_option_opts(opt));
    const std::string what = make_option_desc(opt);
    if (what.empty()) return left + "\n";
    left += left.size() + 2 <= kNameColumn ? std::string(kNameColumn - left.size(), ' ') : std::string("  ");
    return left + what + "\n";
  }

  // The named argument only: CLI11's type, validators and default would repeat the description.
  std::string make_option_opts(const CLI::Option* opt) const override {
    if (!opt->get_option_text().empty()) return " " + opt->get_option_text();
    return opt->get_type_name().empty() ? std::string() : std::string(" VALUE");  // a flag has no type
  }

  std::string make_option_desc(const CLI::Option* opt) const override {
    std::string what = opt->get_description();
    if (!opt->get_default_str().empty()) what += " [default: " + opt->get_default_str() + "]";
    if (opt->get_required() && opt->nonpositional()) what += " [required]";
    return what;
  }

  std::string make_subcommand(const CLI::App* sub) const override {
    std::string left = "  " + sub->get_name();
    left += std::string(left.size() < 12 ? 12 - left.size() : 2, ' ');
    return left + sub->get_description() + "\n";
  }

 private:
  // The option groups in the order the command adds them, the help flag's last.
  std::string groups(const CLI::App* app) const {
    std::vector<std::string> names = app->get_groups();
    const CLI::Option* help = app->get_help_ptr();
    if (help) {
      const auto it = std::find(names.begin(), names.end(), help->get_group());
      if (it != names.end()) std::rotate(it, it + 1, names.end());
    }
    std::string out;
    for (const std::string& group : names) {
      const std::vector<const CLI::Option*> opts = app->get_options(
          [&group](const CLI::Option* o) { return o->get_group() == group && o->nonpositional(); });
      if (!group.empty() && !opts.empty()) out += make_group(group, false, opts);
    }
    return out;
  }
};

size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

}  // namespace

void use_help_formatter(CLI::App& app) {
  auto formatter = std::make_shared<HelpFormatter>();
  formatter->label("Positionals", "Arguments");
  formatter->label("SUBCOMMAND", "COMMAND");
  app.formatter(formatter);
}

std::string closest_name(const std::string& typed, const std::vector<std::string>& names) {
  std::string best;
  if (typed.size() < 3) return best;  // "-x": any short option is as near as another
  size_t best_distance = std::max<size_t>(1, typed.size() / 3) + 1;
  for (const std::string& name : names) {
    const size_t d = edit_distance(typed, name);
    if (d < best_distance) best = name, best_distance = d;
  }
  return best;
}

std::vector<std::string> option_names(const CLI::App& sub) {
  std::vector<std::string> names;
  for (const CLI::Option* opt : sub.get_options()) {
    for (const std::string& n : opt->get_lnames()) names.push_back("--" + n);
    for (const std::string& n : opt->get_snames()) names.push_back("-" + n);
  }
  return names;
}

}  // namespace gibake::cli
