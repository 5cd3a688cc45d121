#include "app/image_overlay.h"

#include <visp3/core/vpException.h>
#include <visp3/core/vpFont.h>
#include <visp3/core/vpImageDraw.h>
#include <visp3/core/vpImagePoint.h>
#include <visp3/io/vpImageIo.h>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <opencv2/imgcodecs.hpp>

#include "matching/lines/undistortion.h"
#include "models/errors.h"
#include "models/geometry.h"

namespace linetrack::app {

vpImage<unsigned char> ReadGreyImage(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw InputError(path + ": no such image file");
  }
  vpImage<unsigned char> image;
  try {
    vpImageIo::read(image, path);
  } catch (const vpException& e) {
    throw InputError(path + ": cannot read the image (" + e.getMessage() + ")");
  } catch (const cv::Exception&) {
    throw InputError(path + ": cannot read the image");
  }
  if (image.getSize() == 0) throw InputError(path + ": the image is empty");
  return image;
}

vpImage<vpRGBa> ColourCopy(const vpImage<unsigned char>& grey) {
  vpImage<vpRGBa> colour(grey.getHeight(), grey.getWidth());
  for (unsigned int i = 0; i < grey.getSize(); ++i) {
    const unsigned char g = grey.bitmap[i];
    colour.bitmap[i] = vpRGBa(g, g, g);
  }
  return colour;
}

void DrawSegments(vpImage<vpRGBa>* image, const std::vector<Segment2>& segments,
                  const vpColor& colour, unsigned int thickness,
                  const std::optional<CameraIntrinsics>& camera) {
  const bool distorted = camera && camera->has_distortion;
  for (const Segment2& s : segments) {
    // A distorted straight line is a curve: draw it as a polyline of pieces ~8 px long.
    const int pieces = distorted ? std::max(1, static_cast<int>(s.Length() / 8.0)) : 1;
    auto at = [&](int k) {
      const Eigen::Vector2d p = s.a + (s.b - s.a) * (static_cast<double>(k) / pieces);
      return distorted ? DistortedPixelOf(*camera, p) : p;
    };
    for (int k = 0; k < pieces; ++k) {
      Segment2 piece{at(k), at(k + 1)};
      // Only what lies inside the image is drawn.
      if (!ClipSegmentToImage(image->getWidth(), image->getHeight(), &piece)) continue;
      vpImageDraw::drawLine(*image, vpImagePoint(piece.a.y(), piece.a.x()),
                            vpImagePoint(piece.b.y(), piece.b.x()), colour, thickness);
    }
  }
}

namespace {

// ViSP's default font at `height` pixels, its monospace font where the default is missing.
std::unique_ptr<vpFont> MakeFont(unsigned int height) {
  try {
    return std::make_unique<vpFont>(height);
  } catch (const vpException&) {
    return std::make_unique<vpFont>(height, vpFont::GENERIC_MONOSPACE);
  }
}

}  // namespace

void DrawTextBox(vpImage<vpRGBa>* image, const std::vector<std::string>& lines) {
  constexpr unsigned int kTextHeight = 14;
  constexpr int kMargin = 4;
  const std::unique_ptr<vpFont> font = MakeFont(kTextHeight);
  double width = 0.0;
  for (const std::string& line : lines)
    width = std::max(width, font->getMeasure(line).get_u());
  const double line_height = kTextHeight + 3.0;
  const double box_w = std::min<double>(width + 2 * kMargin, image->getWidth() - 1);
  const double box_h =
      std::min<double>(lines.size() * line_height + 2 * kMargin, image->getHeight() - 1);
  vpImageDraw::drawRectangle(*image, vpRect(0, 0, box_w, box_h), vpColor(30, 30, 30), true);
  for (size_t k = 0; k < lines.size(); ++k) {
    font->drawText(*image, lines[k], vpImagePoint(kMargin + k * line_height, kMargin),
                   vpColor::white);
  }
}

void DrawLabels(vpImage<vpRGBa>* image, const std::vector<ImageLabel>& labels,
                const vpColor& colour) {
  constexpr unsigned int kTextHeight = 11;
  constexpr double kMargin = 2.0;
  const std::unique_ptr<vpFont> font = MakeFont(kTextHeight);
  const double w = image->getWidth(), h = image->getHeight();
  for (const ImageLabel& label : labels) {
    const double text_w = font->getMeasure(label.text).get_u();
    const double box_w = text_w + 2 * kMargin, box_h = kTextHeight + 2 * kMargin;
    if (box_w >= w || box_h >= h) continue;
    const double left = std::clamp(label.at.x() + 4.0, 0.0, w - 1 - box_w);
    const double top = std::clamp(label.at.y() - box_h / 2, 0.0, h - 1 - box_h);
    vpImageDraw::drawRectangle(*image, vpRect(left, top, box_w, box_h), vpColor(30, 30, 30), true);
    font->drawText(*image, label.text, vpImagePoint(top + kMargin, left + kMargin), colour);
  }
}

std::string EncodePngColour(const vpImage<vpRGBa>& image) {
  cv::Mat bgr(static_cast<int>(image.getHeight()), static_cast<int>(image.getWidth()), CV_8UC3);
  for (unsigned int i = 0; i < image.getHeight(); ++i) {
    cv::Vec3b* row = bgr.ptr<cv::Vec3b>(static_cast<int>(i));
    for (unsigned int j = 0; j < image.getWidth(); ++j) {
      const vpRGBa& p = image[i][j];
      row[j] = cv::Vec3b(p.B, p.G, p.R);
    }
  }
  std::vector<uchar> buffer;
  cv::imencode(".png", bgr, buffer, {cv::IMWRITE_PNG_COMPRESSION, 9});
  return std::string(buffer.begin(), buffer.end());
}

void CheckOutputFolder(const std::string& path, const std::string& flag) {
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  std::error_code ec;
  if (!parent.empty() && !std::filesystem::is_directory(parent, ec)) {
    throw InputError(flag + ": " + path + ": the folder " + parent.string() + " does not exist");
  }
}

void CheckPngOutput(const std::string& path, const std::string& flag) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
  if (ext != ".png") throw InputError(flag + ": " + path + ": overlays are written as .png");
  CheckOutputFolder(path, flag);
}

}  // namespace linetrack::app
