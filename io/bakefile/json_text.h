// JSON for people to read (info text, the HTML report): floats rounded to a few significant digits
// (a float setting such as 0.3 is stored as the double 0.30000001192092896), and the probe grid's
// unset placeholders left out. The stored JSON is never changed: this is only how it is shown.
#pragma once
#include <nlohmann/json.hpp>
#include <string>

namespace gibake {

// Every floating-point number rounded to `digits` significant digits.
nlohmann::json rounded_for_reading(const nlohmann::json& j, int digits = 6);

// `j` as one line of text, like dump(), but a float that is not finite written as nan, inf or -inf:
// JSON has no such numbers (dump() writes null), and a person reading a value must see what it is.
std::string text_of(const nlohmann::json& j);

// A bake's settings JSON as a person reads it: rounded, and in "grid" the fields that only hold
// placeholders (counts [0,0,0] and spacing 0 under the default rule, grid_min/grid_max without
// explicit bounds) left out.
nlohmann::json settings_for_reading(const nlohmann::json& settings);

}  // namespace gibake
