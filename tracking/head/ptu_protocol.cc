#include "tracking/head/ptu_protocol.h"

#include <cctype>
#include <cstdlib>

#include "models/geometry.h"

namespace linetrack {
namespace {

std::string Trim(const std::string& s) {
  const std::size_t b = s.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return {};
  const std::size_t e = s.find_last_not_of(" \t\r\n");
  return s.substr(b, e - b + 1);
}

// An event is "!P" or "!T" not followed by a space (replies are "! message").
bool EventAt(const std::string& s, std::size_t i, char* axis) {
  if (i + 1 >= s.size() || s[i] != '!') return false;
  const char a = static_cast<char>(std::toupper(static_cast<unsigned char>(s[i + 1])));
  if (a != 'P' && a != 'T') return false;
  if (i + 2 < s.size() && s[i + 2] == ' ') return false;
  *axis = a;
  return true;
}

// Parses a number starting at or after `from`; false when there is none.
bool NumberFrom(const std::string& s, std::size_t from, double* value) {
  for (std::size_t i = from; i < s.size(); ++i) {
    const bool digit = std::isdigit(static_cast<unsigned char>(s[i])) != 0;
    const bool signed_digit = (s[i] == '-' || s[i] == '+' || s[i] == '.') && i + 1 < s.size() &&
                              std::isdigit(static_cast<unsigned char>(s[i + 1])) != 0;
    if (!digit && !signed_digit) continue;
    char* end = nullptr;
    const double v = std::strtod(s.c_str() + i, &end);
    if (end == s.c_str() + i) return false;
    *value = v;
    return true;
  }
  return false;
}

}  // namespace

PtuLine ParsePtuLine(const std::string& line) {
  PtuLine parsed;
  std::size_t i = 0;
  char axis = 0;
  while (EventAt(line, i, &axis)) {
    (axis == 'P' ? parsed.pan_limit_events : parsed.tilt_limit_events) += 1;
    i += 2;
  }
  const std::size_t mark = line.find_first_of("*!", i);
  if (mark == std::string::npos) return parsed;  // echo or noise only
  parsed.kind = line[mark] == '*' ? PtuLine::Kind::kSuccess : PtuLine::Kind::kError;
  parsed.text = Trim(line.substr(mark + 1));
  return parsed;
}

bool TakePtuEvents(const std::string& text, int* pan_events, int* tilt_events) {
  if (text.empty()) return false;
  int pan = 0, tilt = 0;
  std::size_t i = 0;
  char axis = 0;
  while (i < text.size() && EventAt(text, i, &axis)) {
    (axis == 'P' ? pan : tilt) += 1;
    i += 2;
  }
  if (i != text.size()) return false;
  *pan_events += pan;
  *tilt_events += tilt;
  return true;
}

bool ParsePtuNumber(const std::string& text, double* value) {
  const std::size_t is = text.find(" is ");
  if (is != std::string::npos && NumberFrom(text, is + 4, value)) return true;
  return NumberFrom(text, 0, value);
}

double PtuCountsToRadians(double counts, double arcsec_per_count, int sign) {
  return sign * counts * arcsec_per_count * kPi / (180.0 * 3600.0);
}

double PtuRadiansToCounts(double radians, double arcsec_per_count, int sign) {
  return sign * radians * (180.0 * 3600.0) / (kPi * arcsec_per_count);
}

}  // namespace linetrack
