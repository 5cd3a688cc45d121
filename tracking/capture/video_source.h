// Replay of recorded frames: printf-style image sequences ("DIR/frame_%05d.png", numbering from
// any index) through ViSP's vpVideoReader, video files through OpenCV's VideoCapture, and
// single images. This is the reader `linetrack replay` uses.
#pragma once

#include <memory>
#include <string>

#include "tracking/capture/frame_source.h"

namespace linetrack {

struct VideoSourceOptions {
  // Frames per second for the timestamps (index / rate); 0 = the video's own rate, or 30 for
  // image sequences (which carry none).
  double frame_rate = 0.0;
  long first_index = -1;  // first frame number of a sequence; -1 = the smallest one on disk
  long last_index = -1;   // last frame number; -1 = the end of the run of consecutive numbers

  bool Check(std::string* why) const;
};

// A printf pattern with exactly one integer conversion ("%d", "%05d"), split for matching.
struct SequencePattern {
  std::string directory;   // "." when the pattern has no directory part
  std::string prefix;      // file name part before the conversion
  std::string suffix;      // file name part after the conversion
  std::string conversion;  // the conversion itself, e.g. "%05d"
};

// Splits `pattern`; false when it has no integer conversion, more than one conversion, or the
// conversion is in the directory part.
bool ParseSequencePattern(const std::string& pattern, SequencePattern* parsed);

// File name of frame `index` ("frame_00042.png").
std::string SequenceFileName(const SequencePattern& pattern, long index);

// The frame numbers present on disk for `pattern`: the smallest one and the end of the run of
// consecutive numbers starting there. False when no file matches.
bool FindSequenceRange(const SequencePattern& pattern, long* first, long* last);

// Frames of an image sequence, video file or single image, converted to grey. The constructor
// throws InputError naming the path when nothing can be read; Grab() throws InputError when a
// frame of a sequence cannot be decoded.
class VideoSource : public FrameSource {
 public:
  VideoSource(const std::string& path, const VideoSourceOptions& options);
  ~VideoSource() override;

  FrameStatus Grab(Frame* frame) override;
  std::string Describe() const override;
  SourceStats Stats() const override;

  // Number of frames, when known (sequences and single images; 0 for videos).
  long FrameCount() const;

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace linetrack
