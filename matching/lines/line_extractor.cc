#include "matching/lines/line_extractor.h"

#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/ximgproc.hpp>
#include <stdexcept>

#include "matching/lines/undistortion.h"
#include "models/errors.h"
#include "models/geometry.h"

namespace linetrack {

std::string LineDetectorName(LineDetectorKind kind) {
  switch (kind) {
    case LineDetectorKind::kHough:
      return "hough";
    case LineDetectorKind::kLsd:
      return "lsd";
    case LineDetectorKind::kFld:
      return "fld";
    case LineDetectorKind::kEdlines:
      return "edlines";
  }
  return "unknown";
}

std::vector<LineDetectorKind> AllLineDetectors() {
  return {LineDetectorKind::kHough, LineDetectorKind::kLsd, LineDetectorKind::kFld,
          LineDetectorKind::kEdlines};
}

std::optional<LineDetectorKind> ParseLineDetector(const std::string& name) {
  for (LineDetectorKind kind : AllLineDetectors()) {
    if (LineDetectorName(kind) == name) return kind;
  }
  return std::nullopt;
}

bool LineExtractionOptions::Check(std::string* why) const {
  if (!(min_length_px >= 2.0 && std::isfinite(min_length_px))) {
    *why = "min_length_px must be finite and >= 2";
    return false;
  }
  if (!(fragment_min_length_px >= 2.0 && fragment_min_length_px <= min_length_px)) {
    *why = "fragment_min_length_px must be in [2, min_length_px]";
    return false;
  }
  if (roi.u < 0 || roi.v < 0 || roi.width < 0 || roi.height < 0) {
    *why = "the region of interest must have non-negative corner and size";
    return false;
  }
  if (!merge_options.Check(why) || !hough.Check(why)) return false;
  if (!(fld.canny_low > 0.0 && fld.canny_high >= fld.canny_low && fld.distance_px > 0.0 &&
        std::isfinite(fld.canny_high + fld.distance_px))) {
    *why = "fld: Canny thresholds must satisfy 0 < low <= high, distance_px > 0";
    return false;
  }
  if (edlines.gradient_threshold < 1 || edlines.anchor_threshold < 0 ||
      !(edlines.sigma > 0.0 && edlines.sigma <= 10.0) ||
      !(edlines.line_fit_error_px > 0.0 && edlines.line_fit_error_px <= 10.0)) {
    *why =
        "edlines: gradient_threshold >= 1, anchor_threshold >= 0, sigma in (0, 10], "
        "line_fit_error_px in (0, 10]";
    return false;
  }
  if (!(lsd.scale > 0.0 && lsd.scale <= 1.0)) {
    *why = "lsd: scale must be in (0, 1]";
    return false;
  }
  return true;
}

struct LineExtractor::Impl {
  LineExtractionOptions options;
  std::optional<CameraIntrinsics> camera;
  std::unique_ptr<HoughLineDetector> hough;
  cv::Ptr<cv::LineSegmentDetector> lsd;
  cv::Ptr<cv::ximgproc::FastLineDetector> fld;
  cv::Ptr<cv::ximgproc::EdgeDrawing> edlines;
  cv::Mat map1, map2, undistorted;  // UndistortionMode::kImage
  std::vector<cv::Vec4f> raw;

  bool Distorted() const { return camera && camera->has_distortion; }

  // Segments of the detector in pixels of `grey`.
  std::vector<Segment2> Detect(const cv::Mat& grey) {
    if (options.detector == LineDetectorKind::kHough) return hough->Detect(grey);
    raw.clear();
    switch (options.detector) {
      case LineDetectorKind::kLsd:
        lsd->detect(grey, raw);
        break;
      case LineDetectorKind::kFld:
        fld->detect(grey, raw);
        break;
      case LineDetectorKind::kEdlines:
        edlines->detectEdges(grey);
        edlines->detectLines(raw);
        break;
      case LineDetectorKind::kHough:
        break;
    }
    std::vector<Segment2> segments;
    segments.reserve(raw.size());
    for (const cv::Vec4f& l : raw) {
      Segment2 s{{l[0], l[1]}, {l[2], l[3]}};
      if (s.Length() >= options.fragment_min_length_px) segments.push_back(s);
    }
    return segments;
  }
};

LineExtractor::LineExtractor(const LineExtractionOptions& options,
                             const std::optional<CameraIntrinsics>& camera)
    : impl_(std::make_unique<Impl>()) {
  std::string why;
  if (!options.Check(&why)) throw InputError("line extraction options: " + why);
  if (camera && !camera->Check(&why)) throw InputError("camera " + camera->name + ": " + why);
  impl_->options = options;
  impl_->camera = camera;
  try {
    switch (options.detector) {
      case LineDetectorKind::kHough: {
        HoughLineOptions hough = options.hough;
        hough.min_length_px = std::min(hough.min_length_px, options.fragment_min_length_px);
        impl_->hough = std::make_unique<HoughLineDetector>(hough);
        break;
      }
      case LineDetectorKind::kLsd:
        impl_->lsd = cv::createLineSegmentDetector(
            options.lsd.refine ? cv::LSD_REFINE_STD : cv::LSD_REFINE_NONE, options.lsd.scale);
        break;
      case LineDetectorKind::kFld:
        impl_->fld = cv::ximgproc::createFastLineDetector(
            static_cast<int>(std::ceil(options.fragment_min_length_px)),
            static_cast<float>(options.fld.distance_px), options.fld.canny_low,
            options.fld.canny_high, /*canny_aperture_size=*/3, /*do_merge=*/false);
        break;
      case LineDetectorKind::kEdlines: {
        impl_->edlines = cv::ximgproc::createEdgeDrawing();
        cv::ximgproc::EdgeDrawing::Params params;
        params.GradientThresholdValue = options.edlines.gradient_threshold;
        params.AnchorThresholdValue = options.edlines.anchor_threshold;
        params.Sigma = static_cast<float>(options.edlines.sigma);
        params.LineFitErrorThreshold = options.edlines.line_fit_error_px;
        params.NFAValidation = options.edlines.nfa_validation;
        params.MinLineLength = static_cast<int>(std::ceil(options.fragment_min_length_px));
        impl_->edlines->setParams(params);
        break;
      }
    }
  } catch (const cv::Exception& e) {
    throw std::runtime_error(std::string("OpenCV: ") + e.what());
  }
}

LineExtractor::~LineExtractor() = default;
LineExtractor::LineExtractor(LineExtractor&&) noexcept = default;
LineExtractor& LineExtractor::operator=(LineExtractor&&) noexcept = default;

const LineExtractionOptions& LineExtractor::options() const {
  return impl_->options;
}

LineExtraction LineExtractor::Extract(const vpImage<unsigned char>& image) {
  if (image.getSize() == 0) throw InputError("the image is empty");
  // vpImage rows are contiguous: wrap without copying (the detectors do not write to it).
  const cv::Mat grey(static_cast<int>(image.getHeight()), static_cast<int>(image.getWidth()),
                     CV_8UC1, const_cast<unsigned char*>(image.bitmap));
  return Extract(grey);
}

LineExtraction LineExtractor::Extract(const cv::Mat& grey) {
  Impl& impl = *impl_;
  const LineExtractionOptions& options = impl.options;
  if (grey.empty()) throw InputError("the image is empty");
  if (grey.type() != CV_8UC1) throw InputError("the image is not 8-bit grey");
  if (impl.camera && impl.camera->width > 0 &&
      (grey.cols != impl.camera->width || grey.rows != impl.camera->height)) {
    throw InputError("the image is " + std::to_string(grey.cols) + "x" + std::to_string(grey.rows) +
                     " but camera " + impl.camera->name + " is " +
                     std::to_string(impl.camera->width) + "x" +
                     std::to_string(impl.camera->height));
  }
  const cv::Rect roi = options.roi.Empty() ? cv::Rect(0, 0, grey.cols, grey.rows)
                                           : cv::Rect(options.roi.u, options.roi.v,
                                                      options.roi.width, options.roi.height);
  if (roi.x + roi.width > grey.cols || roi.y + roi.height > grey.rows) {
    throw InputError("the region of interest leaves the " + std::to_string(grey.cols) + "x" +
                     std::to_string(grey.rows) + " image");
  }
  LineExtraction result;
  try {
    const bool remap = impl.Distorted() && options.undistortion == UndistortionMode::kImage;
    cv::Mat source = grey;
    if (remap) {
      if (impl.map1.cols != grey.cols || impl.map1.rows != grey.rows) {
        BuildUndistortionMaps(*impl.camera, grey.cols, grey.rows, &impl.map1, &impl.map2);
      }
      cv::remap(grey, impl.undistorted, impl.map1, impl.map2, cv::INTER_LINEAR,
                cv::BORDER_REPLICATE);
      source = impl.undistorted;
    }
    std::vector<Segment2> segments = impl.Detect(source(roi));
    result.detected = static_cast<int>(segments.size());
    const Eigen::Vector2d offset(roi.x, roi.y);
    const bool clip = impl.Distorted() && !remap && options.clip_to_image;
    std::vector<Segment2> undistorted;
    undistorted.reserve(segments.size());
    for (Segment2 s : segments) {
      s.a += offset;
      s.b += offset;
      if (impl.Distorted() && !remap) s = UndistortSegment(*impl.camera, s);
      if (!clip || ClipSegmentToImage(grey.cols, grey.rows, &s)) undistorted.push_back(s);
    }
    segments = std::move(undistorted);
    if (options.merge)
      segments = MergeCollinearSegments(std::move(segments), options.merge_options);
    for (const Segment2& s : segments) {
      if (s.Length() >= options.min_length_px) result.segments.push_back(s);
    }
    std::sort(result.segments.begin(), result.segments.end(),
              [](const Segment2& x, const Segment2& y) { return x.Length() > y.Length(); });
  } catch (const cv::Exception& e) {
    throw std::runtime_error(std::string("OpenCV: ") + e.what());
  }
  return result;
}

LineNoise DetectedLineNoise() {
  LineNoise noise;
  noise.offset_px = 1.0;
  noise.angle_deg = 0.3;
  return noise;
}

LineExtractorFunction MakeLineExtractorFunction(const LineExtractionOptions& options,
                                                const std::optional<CameraIntrinsics>& camera) {
  auto extractor = std::make_shared<LineExtractor>(options, camera);
  return [extractor](const vpImage<unsigned char>& image) { return (*extractor)(image); };
}

}  // namespace linetrack
