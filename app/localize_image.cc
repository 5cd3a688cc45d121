#include "app/localize_image.h"

#include <chrono>
#include <iomanip>
#include <set>
#include <sstream>

#include "app/cli_common.h"
#include "app/image_overlay.h"
#include "matching/lines/line_extractor.h"
#include "models/errors.h"
#include "models/occlusion.h"

namespace linetrack::app {

ImageLines ExtractImageLines(const std::string& image_path, const std::string& camera_path,
                             const std::string& camera_name, const LineFlags& flags) {
  const LineExtractionOptions options = flags.Options();
  ImageLines lines;
  lines.camera = LoadCamera(camera_path, camera_name);
  lines.detector = LineDetectorName(options.detector);
  lines.image = ReadGreyImage(image_path);
  LineExtractor extractor(options, lines.camera);
  const auto start = std::chrono::steady_clock::now();
  try {
    lines.segments = extractor.Extract(lines.image).segments;
  } catch (const InputError& e) {
    throw InputError(image_path + ": " + e.what());
  }
  lines.ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return lines;
}

std::string LocalizationOverlayPng(const ImageLines& lines, const WireframeModel& model,
                                   const LocalizationResult& result, double matcher_ms) {
  vpImage<vpRGBa> picture = ColourCopy(lines.image);
  std::set<int> matched_edges, matched_lines;
  for (const auto& [edge, line] : result.matches) {
    matched_edges.insert(edge);
    matched_lines.insert(line);
  }
  std::vector<Segment2> unmatched;
  for (size_t i = 0; i < lines.segments.size(); ++i) {
    if (matched_lines.count(static_cast<int>(i)) == 0) unmatched.push_back(lines.segments[i]);
  }
  DrawSegments(&picture, unmatched, vpColor::red, 1, lines.camera);
  std::ostringstream pose, matches, times;
  pose << std::fixed << std::setprecision(2);
  if (result.found) {
    const OcclusionTester occlusion(model);
    CameraIntrinsics undistorted = lines.camera.Undistorted();
    undistorted.width = static_cast<int>(lines.image.getWidth());
    undistorted.height = static_cast<int>(lines.image.getHeight());
    std::vector<Segment2> projected;
    std::vector<ImageLabel> names;  // each matched edge's name at its middle
    for (const ProjectedEdge& e :
         ProjectVisibleEdges(model, occlusion, result.cam_from_world, undistorted)) {
      if (matched_edges.count(e.edge_id) == 0) continue;
      projected.push_back(e.image);
      const std::string& name = model.edges().at(static_cast<size_t>(e.edge_id)).name;
      names.push_back({name.empty() ? "edge " + std::to_string(e.edge_id) : name,
                       lines.camera.Distort(0.5 * (e.image.a + e.image.b))});
    }
    DrawSegments(&picture, projected, vpColor::green, 2, lines.camera);
    DrawLabels(&picture, names, vpColor::green);
    pose << "x " << result.pose.x << " m, y " << result.pose.y << " m, heading "
         << RadToDeg(WrapAngle(result.pose.heading)) << " deg";
    matches << result.matches.size() << " correspondences, score " << std::setprecision(2)
            << result.score_px << " px";
  } else {
    pose << "no pose: " << result.reason;
    matches << result.hypotheses << " hypotheses verified";
  }
  times << std::fixed << std::setprecision(1) << lines.segments.size() << " lines ("
        << lines.detector << ") " << lines.ms << " ms + matcher " << matcher_ms << " ms";
  DrawTextBox(&picture, {pose.str(), matches.str(), times.str()});
  return EncodePngColour(picture);
}

}  // namespace linetrack::app
