#include "cli/options.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <sstream>

namespace gibake::cli {

Status bad_arg(const std::string& option, const std::string& what) {
  return Status::error(ExitCode::BadArguments, "", option, what);
}

bool parse_numbers(const std::string& text, char sep, size_t n, std::vector<double>& out) {
  out.clear();
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, sep)) {
    try {
      size_t used = 0;
      const double v = std::stod(item, &used);
      if (used != item.size() || !std::isfinite(v)) return false;
      out.push_back(v);
    } catch (...) {
      return false;
    }
  }
  return out.size() == n;
}

namespace {

// Whether every value stays finite as a float (the settings' type).
bool within_float(const std::vector<double>& v) {
  for (double x : v)
    if (!(std::fabs(x) <= double(std::numeric_limits<float>::max()))) return false;
  return true;
}

}  // namespace

Status parse_vec3(const std::string& option, const std::string& text, std::array<float, 3>& out) {
  std::vector<double> v;
  if (!parse_numbers(text, ',', 3, v) || !within_float(v))
    return bad_arg(option, "expected three numbers x,y,z, got '" + text + "'");
  for (int i = 0; i < 3; ++i) out[i] = static_cast<float>(v[i]);
  return Status::ok();
}

Status check_places(const std::string& option, const std::vector<double>& v, size_t first, size_t count,
                    const std::string& text) {
  for (size_t i = first; i < first + count && i < v.size(); ++i)
    if (std::fabs(v[i]) > kMaxSceneCoordinate) {
      char limit[32];
      std::snprintf(limit, sizeof limit, "%g", kMaxSceneCoordinate);
      return bad_arg(option, "places lie within " + std::string(limit) +
                                 " m of the origin (the ray tracer's range), got '" + text + "'");
    }
  return Status::ok();
}

Status parse_place(const std::string& option, const std::string& text, std::array<float, 3>& out) {
  std::vector<double> v;
  if (!parse_numbers(text, ',', 3, v)) return bad_arg(option, "expected three numbers x,y,z, got '" + text + "'");
  GIBAKE_TRY(check_places(option, v, 0, 3, text));
  for (int i = 0; i < 3; ++i) out[i] = static_cast<float>(v[i]);
  return Status::ok();
}

Status parse_sun(const std::string& text, SunLight& sun) {
  const size_t c1 = text.find(':');
  if (c1 == std::string::npos) return bad_arg("--sun", "expected dx,dy,dz:lux[:r,g,b], got '" + text + "'");
  const size_t c2 = text.find(':', c1 + 1);
  GIBAKE_TRY(parse_vec3("--sun", text.substr(0, c1), sun.direction));
  std::vector<double> lux;
  if (!parse_numbers(text.substr(c1 + 1, c2 == std::string::npos ? std::string::npos : c2 - c1 - 1), ',', 1, lux) ||
      lux[0] < 0 || !within_float(lux))
    return bad_arg("--sun", "illuminance (lux) must be a number from 0 to 3.4e38 in '" + text + "'");
  sun.lux = static_cast<float>(lux[0]);
  if (c2 != std::string::npos) GIBAKE_TRY(parse_vec3("--sun", text.substr(c2 + 1), sun.color));
  return Status::ok();
}

Status parse_suns(const std::vector<std::string>& texts, std::vector<SunLight>& suns) {
  for (const std::string& text : texts) {
    SunLight sun;
    GIBAKE_TRY(parse_sun(text, sun));
    suns.push_back(sun);
  }
  return Status::ok();
}

Status parse_on_off(const std::string& option, const std::string& text, bool& out) {
  if (text == "on") out = true;
  else if (text == "off") out = false;
  else return bad_arg(option, "expected 'on' or 'off', got '" + text + "'");
  return Status::ok();
}

Status parse_backend_options(const std::string& backend, const std::string& vulkan_device, BackendSettings& out) {
  if (!parse_backend(backend, out.backend))
    return bad_arg("--backend", "expected 'auto', 'cpu' or 'vulkan', got '" + backend + "'");
  if (!vulkan_device.empty() && out.backend == Backend::Cpu)
    return bad_arg("--vulkan-device", "names a device for --backend vulkan or auto");
  out.vulkan_device = vulkan_device;
  return Status::ok();
}

CLI::Validator whole_number(int64_t lo, int64_t hi) {
  const std::string range = std::to_string(lo) + ".." + std::to_string(hi);
  return CLI::Validator(
      [lo, hi, range](std::string& text) -> std::string {
        std::vector<double> v;
        if (!parse_numbers(text, ',', 1, v) || v[0] != std::floor(v[0]) || v[0] < double(lo) || v[0] > double(hi))
          return "expected a whole number in " + range + ", got '" + text + "'";
        return {};
      },
      "INT in " + range);
}

CLI::Validator positive_number() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        std::vector<double> v;
        if (!parse_numbers(text, ',', 1, v) || !(v[0] > 0.0)) return "expected a number above 0, got '" + text + "'";
        return {};
      },
      "NUMBER > 0");
}

CLI::Validator non_negative_number() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        std::vector<double> v;
        if (!parse_numbers(text, ',', 1, v) || !(v[0] >= 0.0)) return "expected a number, 0 or more, got '" + text + "'";
        return {};
      },
      "NUMBER >= 0");
}

void require_finite_numbers(CLI::App& command) {
  // Text that is no number at all is left to the option's own check and conversion, which say
  // what it takes.
  const CLI::Validator finite(
      [](std::string& text) -> std::string {
        char* end = nullptr;
        const double v = std::strtod(text.c_str(), &end);
        const bool number = !text.empty() && end == text.c_str() + text.size();
        if (number && !(std::fabs(v) <= double(std::numeric_limits<float>::max())))
          return "expected a finite number, got '" + text + "'";
        // Not 0 in the text but 0 as a float: read as 0, it would pass for "unset" where 0 means that.
        if (number && v != 0.0 && float(v) == 0.f) return "'" + text + "' is too small for a float: it would read as 0";
        return {};
      },
      "");
  for (CLI::Option* opt : command.get_options())
    if (opt->get_type_name().rfind("FLOAT", 0) == 0) opt->transform(finite);  // first: before any range check
}

void require_paths(CLI::App& command) {
  // What names a file or folder: a named argument FILE, DIR, EXR or PART..., or a positional SCENE,
  // FILE or PART. An empty path (an unset shell variable) would switch the action off unseen.
  static const char* const kPathArgs[] = {"FILE", "DIR", "EXR", "PART...", "SCENE", "PART"};
  const CLI::Validator non_empty([](std::string& text) { return text.empty() ? "expected a path, got ''" : ""; }, "");
  for (CLI::Option* opt : command.get_options()) {
    const std::string arg = opt->nonpositional() ? opt->get_option_text() : opt->get_name();
    if (std::find(std::begin(kPathArgs), std::end(kPathArgs), arg) != std::end(kPathArgs)) opt->check(non_empty);
  }
}

Status check_view_vectors(const std::string& option, const std::vector<double>& v, const std::string& text) {
  const double f[3] = {v[3] - v[0], v[4] - v[1], v[5] - v[2]};
  if (f[0] == 0.0 && f[1] == 0.0 && f[2] == 0.0)
    return bad_arg(option, "eye and target must differ, got '" + text + "'");
  const double c[3] = {f[1] * v[8] - f[2] * v[7], f[2] * v[6] - f[0] * v[8], f[0] * v[7] - f[1] * v[6]};
  if (c[0] == 0.0 && c[1] == 0.0 && c[2] == 0.0)
    return bad_arg(option, "the up vector must be neither zero nor along the view (eye to target), got '" + text + "'");
  return Status::ok();
}

CLI::Validator unsigned_integer() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        const bool digits = !text.empty() && text.size() <= 20 &&
                            text.find_first_not_of("0123456789") == std::string::npos;
        if (!digits || (text.size() == 20 && text > "18446744073709551615"))
          return "expected a whole number from 0 to 18446744073709551615, got '" + text + "'";
        return {};
      },
      "UINT64");
}

Status check_output_kind(const std::string& option, const std::string& path, std::initializer_list<const char*> own,
                         const std::string& written) {
  static const std::pair<const char*, const char*> kKinds[] = {
      {".gltf", "a glTF scene"},  {".glb", "a glTF scene"},    {".bin", "a glTF buffer or a bake file"},
      {".gibake", "a bake file"}, {".vdb", "an OpenVDB file"}, {".png", "a PNG image"},
      {".jpg", "a JPEG image"},   {".jpeg", "a JPEG image"},   {".ktx2", "a KTX2 image"},
      {".webp", "a WebP image"},  {".exr", "an EXR image"},    {".hdr", "an HDR image"},
      {".json", "a JSON file"},   {".html", "a web page"},     {".csv", "a CSV file"},
      {".txt", "a text file"}};
  const size_t slash = path.find_last_of('/'), dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return Status::ok();
  std::string ext = path.substr(dot);
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  for (const char* mine : own)
    if (ext == mine) return Status::ok();
  for (const auto& [other, kind] : kKinds)
    if (ext == other)
      return Status::error(
          ExitCode::BadArguments, path, option,
          std::string("names ") + kind + ", but " + written + " is written here: name it " + *own.begin());
  return Status::ok();
}

Status check_bake_file_name(const std::string& option, const std::string& path) {
  return check_output_kind(option, path, {".gibake", ".bin"}, "a bake file");
}

CLI::Option* add_threads_option(CLI::App* sub, unsigned& threads, const std::string& what_does_not_depend_on_it,
                                const std::string& group) {
  return sub
      ->add_option("--threads", threads, "worker threads, 0: all (" + what_does_not_depend_on_it + " do not depend on it)")
      ->check(whole_number(0, kMaxThreads))
      ->group(group)
      ->option_text("N")
      ->capture_default_str();
}

}  // namespace gibake::cli
