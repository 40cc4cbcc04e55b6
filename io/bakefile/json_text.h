// JSON for people to read (info text, the HTML report): floats rounded to a few significant digits
// (a float setting such as 0.3 is stored as the double 0.30000001192092896), and the probe grid's
// unset placeholders left out. The stored JSON is never changed: this is only how it is shown.
#pragma once
#include <nlohmann/json.hpp>

namespace gibake {

// Every floating-point number rounded to `digits` significant digits.
nlohmann::json rounded_for_reading(const nlohmann::json& j, int digits = 6);

// A bake's settings JSON as a person reads it: rounded, and in "grid" the fields that only hold
// placeholders (counts [0,0,0] and spacing 0 under the default rule, grid_min/grid_max without
// explicit bounds) left out.
nlohmann::json settings_for_reading(const nlohmann::json& settings);

}  // namespace gibake
