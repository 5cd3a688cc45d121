// `linetrack lines`: line segments of one image, in undistorted pixels, as the CSV that
// `linetrack localize --lines` reads, with an optional overlay.
//   linetrack lines IMAGE [--camera C.xml] [--detector NAME] --out LINES.csv [--overlay OUT.png]
#include <spdlog/spdlog.h>

#include <chrono>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

#include "app/commands.h"
#include "app/image_overlay.h"
#include "app/line_flags.h"
#include "matching/lines/line_extractor.h"
#include "models/errors.h"

namespace linetrack::app {
namespace {

struct LinesCommandOptions {
  std::string image_path, out_path, overlay_path;
  LineFlags lines;
};

std::string FormatLinesCsv(const std::vector<Segment2>& segments) {
  std::ostringstream csv;
  csv << "u1,v1,u2,v2\n" << std::fixed << std::setprecision(3);
  for (const Segment2& s : segments)
    csv << s.a.x() << "," << s.a.y() << "," << s.b.x() << "," << s.b.y() << "\n";
  return csv.str();
}

int RunLines(const LinesCommandOptions& opt) {
  // Everything that can be checked is checked before the work; outputs are written at the end.
  CheckOutputFolder(opt.out_path, "--out");
  if (!opt.overlay_path.empty()) CheckPngOutput(opt.overlay_path, "--overlay");
  const LineExtractionOptions options = opt.lines.Options();
  const std::optional<CameraIntrinsics> camera = opt.lines.Camera();
  const vpImage<unsigned char> image = ReadGreyImage(opt.image_path);
  LineExtractor extractor(options, camera);
  const auto start = std::chrono::steady_clock::now();
  LineExtraction extraction;
  try {
    extraction = extractor.Extract(image);
  } catch (const InputError& e) {
    throw InputError(opt.image_path + ": " + e.what());
  }
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  std::string overlay;
  if (!opt.overlay_path.empty()) {
    vpImage<vpRGBa> picture = ColourCopy(image);
    DrawSegments(&picture, extraction.segments, vpColor::red, 2, camera);
    std::ostringstream text;
    text << extraction.segments.size() << " segments (" << LineDetectorName(options.detector)
         << ", " << std::fixed << std::setprecision(1) << ms << " ms)";
    DrawTextBox(&picture, {text.str()});
    overlay = EncodePngColour(picture);
  }
  WriteFileAtomically(opt.out_path, FormatLinesCsv(extraction.segments));
  if (!overlay.empty()) WriteFileAtomically(opt.overlay_path, overlay);
  std::cout << extraction.segments.size() << " segments (" << extraction.detected << " detected by "
            << LineDetectorName(options.detector) << ", " << std::fixed << std::setprecision(2)
            << ms << " ms) -> " << opt.out_path << std::endl;
  return kExitOk;
}

}  // namespace

void AddLines(CLI::App& cli, CommandAction* action) {
  auto opt = std::make_shared<LinesCommandOptions>();
  CLI::App* cmd = cli.add_subcommand(
      "lines",
      "Line segments of an image in undistorted pixels (CSV u1,v1,u2,v2 as localize --lines "
      "reads)");
  cmd->add_option("IMAGE", opt->image_path, "Grey or colour image (PNG, PGM, JPEG, ...)")
      ->required();
  cmd->add_option("--out", opt->out_path, "CSV of segments u1,v1,u2,v2 (header row)")->required();
  cmd->add_option("--overlay", opt->overlay_path, "PNG of the image with the segments in red");
  AddLineFlags(cmd, &opt->lines);
  cmd->callback([opt, action] { *action = [opt] { return RunLines(*opt); }; });
}

}  // namespace linetrack::app
