// How values are shown to people (io/bakefile/json_text.h).
#include "io/bakefile/json_text.h"

#include <gtest/gtest.h>

#include <limits>

namespace gibake {
namespace {

using nlohmann::json;

// JSON has no NaN or infinity: dump() writes null, which a reader of `info` cannot tell from a
// missing value. The text shows what the value is; finite values read as dump() writes them.
TEST(JsonText, NonFiniteFloatsReadAsWhatTheyAre) {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  const json values = json::array({json::array({1.5, nan}), inf, -inf, 2, "x"});
  EXPECT_EQ(values.dump(), "[[1.5,null],null,null,2,\"x\"]");
  EXPECT_EQ(text_of(values), "[[1.5,nan],inf,-inf,2,\"x\"]");
  const json object{{"a", nan}, {"b", json::array({0.25})}};
  EXPECT_EQ(text_of(object), "{\"a\":nan,\"b\":[0.25]}");
  EXPECT_EQ(text_of(rounded_for_reading(json::array({nan, 0.30000001192092896}))), "[nan,0.3]");
}

}  // namespace
}  // namespace gibake
