// The per-frame truth of a rendered sequence beyond the pose (frame_truth.csv): whether the frame
// is observable, and which effects it carries (covered lens, gain, motion blur, people).
#pragma once

#include <string>
#include <vector>

namespace linetrack {

struct FrameTruth {
  long frame = 0;
  double t = 0.0;               // seconds
  bool observable = false;      // at least the asked number of long, unoccluded model edges
  int observable_edges = 0;     // model edges with a visible, unoccluded piece long enough
  bool covered = false;         // lens covered (blackout)
  double gain = 1.0;            // exposure gain
  int shutter_samples = 1;      // poses averaged over the shutter (motion blur)
  double blur_px = 0.0;         // image motion over the shutter (pixels)
  double people_share = 0.0;    // share of the pixels showing a person
  double clutter_share = 0.0;   // share of the pixels showing unmodelled clutter
  double centre_depth_m = 0.0;  // depth at the image centre (metres; 0: nothing there)
  double pan_deg = 0.0;         // head pan (degrees)
};

// The header line of frame_truth.csv.
inline constexpr const char* kFrameTruthHeader =
    "frame,t,observable,observable_edges,covered,gain,shutter_samples,blur_px,people_share,"
    "clutter_share,centre_depth_m,pan_deg";

// CSV text of `rows` with the header line.
std::string FormatFrameTruth(const std::vector<FrameTruth>& rows);

// Parses frame_truth.csv text (the header, then 12 fields a row; frames increasing). Throws
// InputError naming `source`:line.
std::vector<FrameTruth> ParseFrameTruth(const std::string& text, const std::string& source);

// Reads frame_truth.csv from disk (throws InputError naming the file and line).
std::vector<FrameTruth> ReadFrameTruth(const std::string& path);

}  // namespace linetrack
