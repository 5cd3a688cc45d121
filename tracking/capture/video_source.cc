#include "tracking/capture/video_source.h"

#include <visp3/core/vpException.h>
#include <visp3/io/vpImageIo.h>
#include <visp3/io/vpVideoReader.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <filesystem>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <set>

#include "models/errors.h"

namespace linetrack {
namespace fs = std::filesystem;

namespace {

double HostNow() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

bool IsImageExtension(std::string extension) {
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  static const std::set<std::string> kImages = {".pgm",  ".ppm", ".pnm", ".png", ".jpg",
                                                ".jpeg", ".bmp", ".tif", ".tiff"};
  return kImages.count(extension) > 0;
}

// Parses the file-name part of `name` as frame number for `pattern`; false when it does not
// match (the number must print back to the same name).
bool MatchSequenceName(const SequencePattern& pattern, const std::string& name, long* index) {
  if (name.size() <= pattern.prefix.size() + pattern.suffix.size()) return false;
  if (name.compare(0, pattern.prefix.size(), pattern.prefix) != 0) return false;
  if (name.compare(name.size() - pattern.suffix.size(), pattern.suffix.size(), pattern.suffix) !=
      0) {
    return false;
  }
  const std::string digits = name.substr(
      pattern.prefix.size(), name.size() - pattern.prefix.size() - pattern.suffix.size());
  if (digits.empty() || digits.size() > 12 ||
      digits.find_first_not_of("0123456789") != std::string::npos) {
    return false;
  }
  const long value = std::stol(digits);
  if (SequenceFileName(pattern, value) != name) return false;
  *index = value;
  return true;
}

}  // namespace

bool VideoSourceOptions::Check(std::string* why) const {
  if (!(frame_rate >= 0.0 && frame_rate <= 1e6)) {
    *why = "frame rate must be in [0, 1e6] frames/s (0 = the file's own)";
    return false;
  }
  if (first_index < -1 || last_index < -1) {
    *why = "first and last frame numbers must be >= 0 (-1 = automatic)";
    return false;
  }
  if (first_index >= 0 && last_index >= 0 && last_index < first_index) {
    *why = "last frame number is before the first";
    return false;
  }
  return true;
}

bool ParseSequencePattern(const std::string& pattern, SequencePattern* parsed) {
  const fs::path path(pattern);
  const std::string directory = path.parent_path().string();
  const std::string name = path.filename().string();
  if (directory.find('%') != std::string::npos) return false;
  const std::size_t percent = name.find('%');
  if (percent == std::string::npos || name.find('%', percent + 1) != std::string::npos) {
    return false;
  }
  std::size_t end = percent + 1;
  while (end < name.size() && std::isdigit(static_cast<unsigned char>(name[end])))
    ++end;
  if (end >= name.size() || name[end] != 'd') return false;
  const std::string flags_width = name.substr(percent + 1, end - percent - 1);
  if (flags_width.size() > 3) return false;  // widths beyond 99 are not frame numbers
  parsed->directory = directory.empty() ? "." : directory;
  parsed->prefix = name.substr(0, percent);
  parsed->suffix = name.substr(end + 1);
  parsed->conversion = name.substr(percent, end - percent + 1);
  return true;
}

std::string SequenceFileName(const SequencePattern& pattern, long index) {
  const std::string spec = pattern.conversion.substr(1, pattern.conversion.size() - 2);
  const bool zero_pad = !spec.empty() && spec[0] == '0';
  const std::size_t width = spec.empty() ? 0 : std::stoul(spec);
  std::string digits = std::to_string(index);
  if (digits.size() < width) digits.insert(0, width - digits.size(), zero_pad ? '0' : ' ');
  return pattern.prefix + digits + pattern.suffix;
}

bool FindSequenceRange(const SequencePattern& pattern, long* first, long* last) {
  std::error_code error;
  std::set<long> present;
  for (const fs::directory_entry& entry : fs::directory_iterator(pattern.directory, error)) {
    long index = 0;
    if (MatchSequenceName(pattern, entry.path().filename().string(), &index)) {
      present.insert(index);
    }
  }
  if (error || present.empty()) return false;
  *first = *present.begin();
  long end = *first;
  while (present.count(end + 1) > 0)
    ++end;
  *last = end;
  return true;
}

class VideoSource::Impl {
 public:
  enum class Kind { kSequence, kVideo, kImage };

  Impl(const std::string& path, const VideoSourceOptions& options) : path_(path) {
    std::string why;
    if (!options.Check(&why)) throw InputError(path + ": " + why);
    SequencePattern pattern;
    if (ParseSequencePattern(path, &pattern)) {
      OpenSequence(pattern, options);
    } else if (!fs::exists(path)) {
      throw InputError(path + ": no such file");
    } else if (IsImageExtension(fs::path(path).extension().string())) {
      kind_ = Kind::kImage;
      frame_rate_ = options.frame_rate > 0.0 ? options.frame_rate : 30.0;
      count_ = 1;
    } else {
      OpenVideo(options);
    }
  }

  FrameStatus Grab(Frame* frame) {
    FrameStatus status = FrameStatus::kEndOfStream;
    switch (kind_) {
      case Kind::kSequence:
        status = GrabSequence(frame);
        break;
      case Kind::kVideo:
        status = GrabVideo(frame);
        break;
      case Kind::kImage:
        status = GrabImage(frame);
        break;
    }
    if (status == FrameStatus::kOk) {
      frame->index = stats_.delivered++;
      frame->timestamp_s = static_cast<double>(frame->index) / frame_rate_;
      frame->has_camera_timestamp = false;
      frame->host_time_s = HostNow();
    }
    return status;
  }

  std::string Describe() const {
    switch (kind_) {
      case Kind::kSequence:
        return "sequence " + path_ + " (frames " + std::to_string(first_) + ".." +
               std::to_string(last_) + ", " + std::to_string(frame_rate_) + " fps)";
      case Kind::kVideo:
        return "video " + path_ + " (" + std::to_string(frame_rate_) + " fps)";
      case Kind::kImage:
        return "image " + path_;
    }
    return path_;
  }

  SourceStats Stats() const { return stats_; }
  long FrameCount() const { return count_; }

 private:
  void OpenSequence(const SequencePattern& pattern, const VideoSourceOptions& options) {
    kind_ = Kind::kSequence;
    if (!fs::is_directory(pattern.directory)) {
      throw InputError(path_ + ": no such directory '" + pattern.directory + "'");
    }
    long first = 0, last = 0;
    if (!FindSequenceRange(pattern, &first, &last)) {
      throw InputError(path_ + ": no file matches the pattern");
    }
    first_ = options.first_index >= 0 ? options.first_index : first;
    last_ = options.last_index >= 0 ? options.last_index : last;
    if (first_ < first || last_ > last || first_ > last_) {
      throw InputError(path_ + ": frames " + std::to_string(first_) + ".." + std::to_string(last_) +
                       " requested, frames " + std::to_string(first) + ".." + std::to_string(last) +
                       " present");
    }
    count_ = last_ - first_ + 1;
    frame_rate_ = options.frame_rate > 0.0 ? options.frame_rate : 30.0;
    try {
      reader_.setFileName(path_);
      reader_.setFirstFrameIndex(first_);
      reader_.setLastFrameIndex(last_);
      vpImage<unsigned char> first_image;
      reader_.open(first_image);  // reads the first frame; acquire() then starts from it again
    } catch (const vpException& e) {
      throw InputError(path_ + ": " + e.getStringMessage());
    }
  }

  void OpenVideo(const VideoSourceOptions& options) {
    kind_ = Kind::kVideo;
    if (!capture_.open(path_) || !capture_.isOpened()) {
      throw InputError(path_ + ": not a readable video or image file");
    }
    const double file_rate = capture_.get(cv::CAP_PROP_FPS);
    frame_rate_ = options.frame_rate > 0.0
                      ? options.frame_rate
                      : (file_rate > 0.0 && file_rate < 1e4 ? file_rate : 30.0);
  }

  // Sequences: vpVideoReader, stopping at end() (the last frame number is known).
  FrameStatus GrabSequence(Frame* frame) {
    if (next_ > last_ - first_) return FrameStatus::kEndOfStream;
    try {
      reader_.acquire(frame->image);
    } catch (const vpException& e) {
      throw InputError(path_ + ": frame " + std::to_string(first_ + next_) + ": " +
                       e.getStringMessage());
    }
    if (frame->image.getSize() == 0) {
      throw InputError(path_ + ": frame " + std::to_string(first_ + next_) + " is empty");
    }
    // vpVideoReader skips a file it cannot decode and hands over the next one instead.
    if (reader_.getFrameIndex() != first_ + next_) {
      throw InputError(path_ + ": frame " + std::to_string(first_ + next_) + " cannot be decoded");
    }
    frame->frame_id = static_cast<std::uint64_t>(reader_.getFrameIndex());
    ++next_;
    return FrameStatus::kOk;
  }

  // Videos: OpenCV's VideoCapture read sequentially; read() fails at the end. (vpVideoReader
  // on a raw MPEG-1 reports one frame, skips frames and never reaches end() with grey images.)
  FrameStatus GrabVideo(Frame* frame) {
    if (!capture_.read(bgr_) || bgr_.empty()) return FrameStatus::kEndOfStream;
    if (frame->image.getWidth() != static_cast<unsigned>(bgr_.cols) ||
        frame->image.getHeight() != static_cast<unsigned>(bgr_.rows)) {
      frame->image.resize(bgr_.rows, bgr_.cols);
    }
    cv::Mat grey(bgr_.rows, bgr_.cols, CV_8UC1, frame->image.bitmap);
    if (bgr_.channels() == 1 && bgr_.depth() == CV_8U) {
      bgr_.copyTo(grey);
    } else if (bgr_.channels() == 3 && bgr_.depth() == CV_8U) {
      cv::cvtColor(bgr_, grey, cv::COLOR_BGR2GRAY);
    } else if (bgr_.channels() == 4 && bgr_.depth() == CV_8U) {
      cv::cvtColor(bgr_, grey, cv::COLOR_BGRA2GRAY);
    } else {
      throw InputError(path_ + ": frame " + std::to_string(next_) +
                       " has an unsupported pixel type");
    }
    frame->frame_id = static_cast<std::uint64_t>(next_++);
    return FrameStatus::kOk;
  }

  FrameStatus GrabImage(Frame* frame) {
    if (next_ > 0) return FrameStatus::kEndOfStream;
    try {
      vpImageIo::read(frame->image, path_);
    } catch (const vpException& e) {
      throw InputError(path_ + ": " + e.getStringMessage());
    }
    if (frame->image.getSize() == 0) throw InputError(path_ + ": empty image");
    frame->frame_id = static_cast<std::uint64_t>(next_++);
    return FrameStatus::kOk;
  }

  std::string path_;
  Kind kind_ = Kind::kVideo;
  vpVideoReader reader_;
  cv::VideoCapture capture_;
  cv::Mat bgr_;
  long first_ = 0, last_ = 0, next_ = 0, count_ = 0;
  double frame_rate_ = 30.0;
  SourceStats stats_;
};

VideoSource::VideoSource(const std::string& path, const VideoSourceOptions& options)
    : impl_(std::make_unique<Impl>(path, options)) {}
VideoSource::~VideoSource() = default;
FrameStatus VideoSource::Grab(Frame* frame) {
  return impl_->Grab(frame);
}
std::string VideoSource::Describe() const {
  return impl_->Describe();
}
SourceStats VideoSource::Stats() const {
  return impl_->Stats();
}
long VideoSource::FrameCount() const {
  return impl_->FrameCount();
}

}  // namespace linetrack
