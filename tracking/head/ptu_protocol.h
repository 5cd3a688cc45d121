// The ASCII protocol of FLIR (Directed Perception) PTU-D46/E46 pan-tilt units, the subset
// linetrack uses (PTU-D46 user's manual v2.14, section 4; docs/live.md lists it):
//   commands  <axis><op>[<signed integer>] followed by a delimiter (space or CR), axis P or T:
//             PP/TP position (counts), PS/TS speed (counts/s), PR/TR resolution (arc-seconds per
//             count), PN/PX/TN/TX position limits, PU/TU maximum speeds, PL/TL minimum speeds;
//             CI/CV independent-position / pure-velocity control, H/HP/HT halt, ED/EE echo,
//             FT/FV terse/verbose feedback, I immediate execution, A await.
//   replies   "*" success, "* <result>" query result ("* 1000" terse, "* Current Pan position
//             is 1000" verbose), "! <message>" failure; with echo on, the command text comes
//             first on the line ("PP * 1000"). Lines end with CR (and LF).
//   events    "!P" / "!T" sent on their own when an axis hits a limit (pure velocity mode).
#pragma once

#include <string>

namespace linetrack {

// One line from the unit, with its asynchronous limit events taken apart.
struct PtuLine {
  enum class Kind { kNone, kSuccess, kError };
  Kind kind = Kind::kNone;    // kNone: the line held only events, echo or noise
  std::string text;           // what follows '*' or '!', trimmed
  int pan_limit_events = 0;   // "!P" seen
  int tilt_limit_events = 0;  // "!T" seen
};

// Parses one line (without its terminator). Leading "!P"/"!T" events are counted and removed,
// echoed command text before the '*' or '!' is skipped.
PtuLine ParsePtuLine(const std::string& line);

// True when `text` is made only of "!P"/"!T" events (a partial line may hold them); counts them.
bool TakePtuEvents(const std::string& text, int* pan_events, int* tilt_events);

// The number in a query result: the first number of a terse result ("1000"), or in verbose text
// the number after " is " ("Current Pan position is -500") or else the first number
// ("185.1428 seconds arc per position"). False when there is none.
bool ParsePtuNumber(const std::string& text, double* value);

// Position conversions: radians = sign * counts * arcsec_per_count * pi / (180 * 3600).
double PtuCountsToRadians(double counts, double arcsec_per_count, int sign);
double PtuRadiansToCounts(double radians, double arcsec_per_count, int sign);

}  // namespace linetrack
