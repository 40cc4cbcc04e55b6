#include "io/bakefile/json_text.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace gibake {

nlohmann::json rounded_for_reading(const nlohmann::json& j, int digits) {
  if (j.is_number_float()) {
    char text[64];
    std::snprintf(text, sizeof text, "%.*g", digits, j.get<double>());
    return std::strtod(text, nullptr);
  }
  if (j.is_array() || j.is_object()) {
    nlohmann::json out = j;
    for (auto it = out.begin(); it != out.end(); ++it) *it = rounded_for_reading(*it, digits);
    return out;
  }
  return j;
}

std::string text_of(const nlohmann::json& j) {
  if (j.is_number_float()) {
    const double x = j.get<double>();
    if (std::isnan(x)) return "nan";
    if (std::isinf(x)) return x > 0.0 ? "inf" : "-inf";
    return j.dump();
  }
  if (!j.is_array() && !j.is_object()) return j.dump();
  std::string out(1, j.is_array() ? '[' : '{');
  for (auto it = j.begin(); it != j.end(); ++it) {
    if (it != j.begin()) out += ',';
    if (j.is_object()) out += nlohmann::json(it.key()).dump() + ':';
    out += text_of(*it);
  }
  return out + (j.is_array() ? ']' : '}');
}

nlohmann::json settings_for_reading(const nlohmann::json& settings) {
  nlohmann::json out = rounded_for_reading(settings);
  if (!out.is_object() || !out.contains("grid") || !out["grid"].is_object()) return out;
  nlohmann::json& grid = out["grid"];
  auto all_zero = [](const nlohmann::json& v) {
    if (!v.is_array()) return false;
    for (const auto& x : v)
      if (!x.is_number() || x.get<double>() != 0.0) return false;
    return true;
  };
  if (grid.contains("counts") && all_zero(grid["counts"])) grid.erase("counts");
  if (grid.contains("spacing") && grid["spacing"].is_number() && grid["spacing"].get<double>() == 0.0)
    grid.erase("spacing");
  if (grid.value("explicit_bounds", true) == false) {
    grid.erase("grid_min");
    grid.erase("grid_max");
    grid.erase("explicit_bounds");
  }
  return out;
}

}  // namespace gibake
