// Images of the app: grey images read with one clear error, and overlays drawn into colour
// copies without any display (vpImageDraw, vpFont), encoded as PNG in memory so that they can
// be written atomically.
#pragma once

#include <visp3/core/vpColor.h>
#include <visp3/core/vpImage.h>
#include <visp3/core/vpRGBa.h>
#include <optional>
#include <string>
#include <vector>

#include "models/camera.h"
#include "models/geometry.h"

namespace linetrack::app {

// Reads an image file as 8-bit grey (colour files are converted). Throws InputError naming the
// file when it cannot be read or is empty.
vpImage<unsigned char> ReadGreyImage(const std::string& path);

// A colour copy of a grey image, to draw on.
vpImage<vpRGBa> ColourCopy(const vpImage<unsigned char>& grey);

// Draws segments given in undistorted pixels onto the image as the camera saw it: with a
// distorting `camera`, each segment is drawn as the curve it images (its points distorted).
void DrawSegments(vpImage<vpRGBa>* image, const std::vector<Segment2>& segments,
                  const vpColor& colour, unsigned int thickness,
                  const std::optional<CameraIntrinsics>& camera);

// A box of text lines (white on a dark background) at the top-left corner.
void DrawTextBox(vpImage<vpRGBa>* image, const std::vector<std::string>& lines);

// A small label (`colour` on a dark background) beside each image point (column, row), kept
// inside the image.
struct ImageLabel {
  std::string text;
  Eigen::Vector2d at;
};
void DrawLabels(vpImage<vpRGBa>* image, const std::vector<ImageLabel>& labels,
                const vpColor& colour);

// The PNG file content of a colour image.
std::string EncodePngColour(const vpImage<vpRGBa>& image);

// Throws InputError unless `path` names a .png file in an existing folder (checked before any
// work, so that a bad flag leaves no partial outputs). `flag` names the option.
void CheckPngOutput(const std::string& path, const std::string& flag);

// Throws InputError unless the folder of `path` exists.
void CheckOutputFolder(const std::string& path, const std::string& flag);

}  // namespace linetrack::app
