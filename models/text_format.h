// Small formatting and timing helpers shared by the libraries and the application.
#pragma once

#include <chrono>
#include <cstdio>
#include <string>

namespace linetrack {

// `value` in fixed notation with `decimals` digits after the point ("%.*f").
inline std::string Fixed(double value, int decimals = 2) {
  char text[64];
  std::snprintf(text, sizeof(text), "%.*f", decimals, value);
  return text;
}

// Milliseconds elapsed on the steady clock since `start`.
inline double MillisecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

}  // namespace linetrack
