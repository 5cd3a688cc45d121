// `linetrack views`: key views of a model on a grid of the navigable area, and positioning of an
// image from them by the linear combination of two views (matching/views/, docs/views.md).
//   linetrack views build --model M.cao --camera C.xml --grid 1.0,30 [--height H] [--tilt DEG]
//                         [--render [--clutter N] [--seed S]] --out DIR
//   linetrack views localize IMAGE --views DIR [--camera C.xml] [--json]
//   linetrack views localize --lines LINES.csv --views DIR [--json]
#include <spdlog/spdlog.h>

#include <chrono>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "app/commands.h"
#include "app/image_overlay.h"
#include "app/line_flags.h"
#include "app/lines_csv.h"
#include "app/localize_image.h"
#include "app/localize_io.h"
#include "app/model_loading.h"
#include "app/rendered_key_view.h"
#include "matching/views/view_positioning.h"
#include "matching/views/view_store.h"
#include "models/errors.h"
#include "models/navigable_area.h"

namespace linetrack::app {
namespace {

struct ViewsBuildOptions {
  std::string model_path, camera_path, camera_name, grid = "1.0,30", out;
  double height = 1.3, tilt_deg = 5.0;
  bool render = false;
  int clutter = 0;
  uint64_t seed = 1;
  LineFlags lines;
};

struct ViewsLocalizeOptions {
  std::string image_path, lines_path, views_dir;
  bool json = false;
  LineFlags lines;
};

ViewGrid ParseGrid(const ViewsBuildOptions& opt) {
  const std::vector<double> v = ParseNumbers(opt.grid, 2, "--grid");
  ViewGrid grid;
  grid.step = v[0];
  grid.heading_step = DegToRad(v[1]);
  grid.height = opt.height;
  grid.tilt = DegToRad(opt.tilt_deg);
  std::string why;
  if (!grid.Check(&why)) throw InputError("--grid/--height/--tilt: " + why);
  return grid;
}

int RunViewsBuild(const ViewsBuildOptions& opt) {
  const ViewGrid grid = ParseGrid(opt);
  const WireframeModel model = LoadModel(opt.model_path);
  const NavigableArea area = NavigableArea::FromModel(model);
  const CameraIntrinsics camera = ReadCameraXml(opt.camera_path, opt.camera_name);
  if (camera.width <= 0)
    throw InputError(opt.camera_path + ": the camera file gives no image size");
  std::unique_ptr<KeyViewRenderer> renderer;
  if (opt.render) {
    renderer = std::make_unique<KeyViewRenderer>(
        model, area, camera, KeyViewRenderOptions{opt.clutter, opt.seed, opt.lines.Options()});
  }
  const OcclusionTester occlusion(model);
  ViewDatabase db;
  db.camera = camera.Undistorted();
  db.model_path = opt.model_path;
  const std::vector<RobotPose> poses = GridPoses(area, grid);
  const auto start = std::chrono::steady_clock::now();
  for (size_t i = 0; i < poses.size(); ++i) {
    const std::vector<ProjectedEdge> pieces =
        ProjectVisibleEdges(model, occlusion, CamFromWorld(poses[i]), db.camera);
    KeyView view = renderer ? renderer->Render(pieces, poses[i], static_cast<int>(i))
                            : KeyViewFromEdges(model, pieces, poses[i], {});
    view.id = static_cast<int>(db.views.size());
    db.views.push_back(std::move(view));
    if ((i + 1) % 200 == 0) spdlog::info("{}/{} key views", i + 1, poses.size());
  }
  std::string lines;
  size_t segments = 0, junctions = 0;
  for (const KeyView& v : db.views) {
    lines += KeyViewJsonLine(v);
    segments += v.segments.size();
    junctions += v.junctions.size();
  }
  EnsureDirectory(opt.out);
  WriteFileAtomically(opt.out + "/" + kViewLinesFile, lines);
  WriteFileAtomically(opt.out + "/" + kViewIndexFile, ViewIndexJson(db));
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cout << db.views.size() << " key views (" << segments << " segments, " << junctions
            << " junctions" << (opt.render ? ", rendered" : ", projected") << ") in " << std::fixed
            << std::setprecision(1) << s << " s -> " << opt.out << std::endl;
  return kExitOk;
}

nlohmann::ordered_json PoseJson(const RobotPose& p) {
  return {{"x", p.x},
          {"y", p.y},
          {"heading_deg", RadToDeg(p.heading)},
          {"height", p.height},
          {"tilt_deg", RadToDeg(p.tilt)}};
}

nlohmann::ordered_json PositioningJson(const ViewPositioning& r, const ViewDatabase& db,
                                       const std::vector<RetrievedView>& ranked, double ms) {
  nlohmann::ordered_json j;
  j["found"] = r.found;
  j["valid"] = r.found && r.weak_perspective_ok;
  if (!r.found) j["reason"] = r.reason;
  if (r.found) {
    nlohmann::ordered_json pose = PoseJson(r.pose);
    pose["roll_deg"] = RadToDeg(r.roll);
    j["pose"] = pose;
    j["model_views"] = {db.views[r.view1].id, db.views[r.view2].id};
    j["points"] = r.points;
    j["inliers"] = r.inliers;
    j["reference_depth_m"] = r.reference_depth;
    j["rms_px"] = r.rms_px;
    j["weak_perspective"] = {{"scale_a", r.scale_a},
                             {"scale_b", r.scale_b},
                             {"orthogonality", r.orthogonality},
                             {"ok", r.weak_perspective_ok}};
  }
  j["retrieved"] = nlohmann::ordered_json::array();
  for (const RetrievedView& v : ranked) {
    j["retrieved"].push_back({{"view", db.views[v.view].id},
                              {"score", v.score},
                              {"matched_tokens", v.matched_tokens},
                              {"pose", PoseJson(db.views[v.view].pose)}});
  }
  j["time_ms"] = ms;
  return j;
}

void PrintPositioning(const ViewPositioning& r, const ViewDatabase& db) {
  std::cout << std::fixed << std::setprecision(2);
  if (!r.found) {
    std::cout << "no position: " << r.reason << std::endl;
    return;
  }
  std::cout << "x " << r.pose.x << " m, y " << r.pose.y << " m, heading "
            << RadToDeg(r.pose.heading) << " deg, height " << r.pose.height << " m, tilt "
            << RadToDeg(r.pose.tilt) << " deg (model views " << db.views[r.view1].id << " and "
            << db.views[r.view2].id << ", " << r.inliers << "/" << r.points << " junctions)\n"
            << "weak perspective " << (r.weak_perspective_ok ? "holds" : "does NOT hold")
            << ": scales " << std::setprecision(4) << r.scale_a << " / " << r.scale_b
            << ", orthogonality " << r.orthogonality << ", residual " << std::setprecision(2)
            << r.rms_px << " px" << std::endl;
}

int RunViewsLocalize(const ViewsLocalizeOptions& opt) {
  if (opt.image_path.empty() == opt.lines_path.empty()) {
    throw InputError("views localize: give either IMAGE or --lines");
  }
  const ViewDatabase db = LoadViewDatabase(opt.views_dir);
  std::vector<Segment2> lines;
  if (!opt.image_path.empty()) {
    if (opt.lines.camera_path.empty()) {
      LineExtractor extractor(opt.lines.Options(), db.camera);
      lines = extractor(ReadGreyImage(opt.image_path));
    } else {
      lines =
          ExtractImageLines(opt.image_path, opt.lines.camera_path, opt.lines.camera_name, opt.lines)
              .segments;
    }
  } else {
    lines = ReadLinesCsv(opt.lines_path);
  }
  const ViewPositioningOptions options;
  const auto start = std::chrono::steady_clock::now();
  const ViewPositioning result = LocalizeFromViews(lines, db, options);
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  if (opt.json) {
    const std::vector<RetrievedView> ranked = RetrieveViews(lines, db, options.retrieval);
    std::cout << PositioningJson(result, db, ranked, ms).dump(2) << std::endl;
  } else {
    PrintPositioning(result, db);
  }
  return result.found && result.weak_perspective_ok ? kExitOk : kExitJobFailed;
}

void AddViewsBuild(CLI::App* views, CommandAction* action) {
  auto opt = std::make_shared<ViewsBuildOptions>();
  CLI::App* cmd = views->add_subcommand(
      "build", "Key views of a model on a grid of its navigable area (docs/views.md)");
  cmd->add_option("--model", opt->model_path, "Wireframe model (.cao)")->required();
  cmd->add_option("--camera", opt->camera_path, "ViSP camera XML (with the image size)")
      ->required();
  cmd->add_option("--camera-name", opt->camera_name, "Camera name in the XML (default: first)");
  cmd->add_option("--grid", opt->grid, "STEP_M,HEADING_STEP_DEG")->capture_default_str();
  cmd->add_option("--height", opt->height, "Camera height (metres)")->capture_default_str();
  cmd->add_option("--tilt", opt->tilt_deg, "Camera tilt (degrees, positive down)")
      ->capture_default_str();
  cmd->add_flag("--render", opt->render,
                "Segments from rendered images (detected lines, their ids from the model) "
                "instead of the projected edges");
  cmd->add_option("--clutter", opt->clutter, "With --render: unmodelled objects in the scene")
      ->capture_default_str();
  cmd->add_option("--seed", opt->seed, "With --render: seed of the scene and images")
      ->capture_default_str();
  cmd->add_option("--out", opt->out, "Directory of the view database")->required();
  AddLineFlags(cmd, &opt->lines, /*with_camera=*/false);
  cmd->callback([opt, action] {
    if (opt->clutter < 0) throw CLI::ValidationError("--clutter", "must be >= 0");
    CheckRange(opt->height, 0.01, 100.0, "--height");
    CheckRange(opt->tilt_deg, -89.0, 89.0, "--tilt");
    *action = [opt] { return RunViewsBuild(*opt); };
  });
}

void AddViewsLocalize(CLI::App* views, CommandAction* action) {
  auto opt = std::make_shared<ViewsLocalizeOptions>();
  CLI::App* cmd = views->add_subcommand(
      "localize",
      "Camera pose from two stored key views by the linear combination of views, with the "
      "weak-perspective check (no 3D model used)");
  cmd->add_option("IMAGE", opt->image_path, "Grey or colour image (lines extracted as `lines`)");
  cmd->add_option("--lines", opt->lines_path, "CSV of segments u1,v1,u2,v2 (undistorted pixels)");
  cmd->add_option("--views", opt->views_dir, "Directory of the view database")->required();
  cmd->add_flag("--json", opt->json, "Print the result as JSON");
  AddLineFlags(cmd, &opt->lines);
  cmd->callback([opt, action] { *action = [opt] { return RunViewsLocalize(*opt); }; });
}

}  // namespace

void AddViews(CLI::App& cli, CommandAction* action) {
  CLI::App* views = cli.add_subcommand(
      "views", "Key views: build a database on a grid, localise an image from it (docs/views.md)");
  views->require_subcommand(1);
  AddViewsBuild(views, action);
  AddViewsLocalize(views, action);
}

}  // namespace linetrack::app
