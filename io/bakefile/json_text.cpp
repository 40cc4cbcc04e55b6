#include "io/bakefile/json_text.h"

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
