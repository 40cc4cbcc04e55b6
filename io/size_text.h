// Byte counts in messages, as people write them: "1 byte", "512 KiB", "1.5 MiB", "16 GiB".
#pragma once
#include <cstdio>
#include <string>

namespace gibake {

// Powers of 1024, three significant digits below 100 of a unit, whole units above (no exponents).
inline std::string size_text(double bytes) {
  static const char* const kUnits[] = {"KiB", "MiB", "GiB", "TiB", "PiB", "EiB"};
  char text[48];
  if (bytes < 1024.0) {
    std::snprintf(text, sizeof text, "%.0f byte%s", bytes, bytes == 1.0 ? "" : "s");
    return text;
  }
  int unit = -1;
  while (bytes >= 1024.0 && unit < 5) {
    bytes /= 1024.0;
    ++unit;
  }
  std::snprintf(text, sizeof text, bytes < 99.95 ? "%.3g %s" : "%.0f %s", bytes, kUnits[unit]);
  return text;
}

}  // namespace gibake
