// Frame sources from spec strings, as the command line gives them:
//   aravis            the first camera Aravis finds
//   aravis:ID         a camera by Aravis id, serial number, MAC or IPv4 address
//   v4l2:/dev/videoN  a V4L2 device (v4l2 alone: /dev/video0)
//   sim[:ARGS]        the simulated camera (provided by whoever renders it: see make_sim)
//   PATH              a video file, a single image, or a printf image sequence "DIR/f_%05d.png"
//   file:PATH         the same, for paths that would read as one of the prefixes above
#pragma once

#include <functional>
#include <memory>
#include <string>

#include "tracking/capture/aravis_source.h"
#include "tracking/capture/frame_source.h"
#include "tracking/capture/v4l2_source.h"
#include "tracking/capture/video_source.h"

namespace linetrack {

enum class SourceKind { kAravis, kV4l2, kVideo, kSim };

// A parsed spec: the kind and what follows the prefix (device id, device path, file path or the
// simulator's arguments; may be empty).
struct SourceSpec {
  SourceKind kind = SourceKind::kVideo;
  std::string argument;
};

// Parses a spec string; throws InputError on an empty spec.
SourceSpec ParseSourceSpec(const std::string& spec);

// Makes the simulated camera from the text after "sim:" (the renderer lives elsewhere).
using SimSourceMaker = std::function<std::unique_ptr<FrameSource>(const std::string& arguments)>;

// Settings for every kind of source; only the one the spec picks is used.
struct FrameSourceOptions {
  AravisSourceOptions aravis;  // device_id is taken from the spec
  V4l2SourceOptions v4l2;
  VideoSourceOptions video;
  SimSourceMaker make_sim;  // empty: "sim" is refused with an InputError
};

// Opens the source the spec names. Throws InputError (naming the spec) when it cannot.
std::unique_ptr<FrameSource> OpenFrameSource(const std::string& spec,
                                             const FrameSourceOptions& options);

}  // namespace linetrack
