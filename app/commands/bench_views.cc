// `linetrack bench views`: key-view retrieval and positioning by the linear combination of
// views. (1) Retrieval on rendered views at random poses against a grid database: is the
// nearest stored view ranked first, top-k recall of a view within one grid step, precision of
// the transferred line ids, time. (2) Positioning from two stored views on the same images.
// (3) Weak perspective alone: exact perspective projections of a box of points, error against
// distance and depth range.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <iomanip>
#include <iostream>
#include <memory>
#include <opencv2/core/utility.hpp>
#include <random>
#include <sstream>

#include "app/commands.h"
#include "app/model_loading.h"
#include "app/rendered_key_view.h"
#include "matching/evaluation/line_evaluation.h"
#include "matching/views/view_positioning.h"
#include "models/errors.h"
#include "models/statistics.h"
#include "models/synth/synthetic_scenes.h"
#include "models/text_format.h"

namespace linetrack::app {
namespace {

struct BenchViewsOptions {
  std::string model_path = "models/hall.cao";
  std::string camera_path;  // empty: the paper's camera
  std::string grid = "1.0,30";
  double height = 1.3, tilt_deg = 5.0;
  int count = 100;
  uint64_t seed = 1;
  int clutter = 10;
  bool render_db = false;
  std::string out_path;
};

// A query: a rendered view at a random pose with its detected lines and their true edge ids.
struct Query {
  RobotPose truth;
  std::vector<Segment2> lines;
  std::vector<std::vector<int>> true_ids;
};

struct Setup {
  WireframeModel model;
  NavigableArea area;
  CameraIntrinsics camera;
  ViewGrid grid;
};

ViewDatabase BuildDatabase(const Setup& s, const BenchViewsOptions& opt) {
  const OcclusionTester occlusion(s.model);
  ViewDatabase db;
  db.camera = s.camera.Undistorted();
  std::unique_ptr<KeyViewRenderer> renderer;
  if (opt.render_db) {
    renderer = std::make_unique<KeyViewRenderer>(s.model, s.area, s.camera,
                                                 KeyViewRenderOptions{0, opt.seed, {}});
  }
  for (const RobotPose& pose : GridPoses(s.area, s.grid)) {
    const auto pieces = ProjectVisibleEdges(s.model, occlusion, CamFromWorld(pose), db.camera);
    KeyView v = renderer ? renderer->Render(pieces, pose, static_cast<int>(db.views.size()))
                         : KeyViewFromEdges(s.model, pieces, pose, {});
    v.id = static_cast<int>(db.views.size());
    db.views.push_back(std::move(v));
  }
  ComputeViewTokens(&db);
  return db;
}

// Queries at random poses: rendered with `clutter` objects and their lines detected, or with
// clutter < 0 the exact visible edge pieces (at least 20 px).
std::vector<Query> RenderQueries(const Setup& s, const BenchViewsOptions& opt, int clutter) {
  KeyViewRenderer renderer(s.model, s.area, s.camera,
                           KeyViewRenderOptions{std::max(0, clutter), opt.seed + 1000, {}});
  const OcclusionTester occlusion(s.model);
  std::vector<Query> out;
  const Eigen::Vector2d lo = s.area.BoundsMin(), hi = s.area.BoundsMax();
  for (int i = 0; i < opt.count; ++i) {
    SceneRandom random(opt.seed, static_cast<uint64_t>(i));
    Query q;
    do {
      q.truth = {random.Uniform(lo.x(), hi.x()), random.Uniform(lo.y(), hi.y()),
                 random.Uniform(-kPi, kPi), s.grid.height, s.grid.tilt};
    } while (!s.area.Contains({q.truth.x, q.truth.y}));
    const std::vector<ProjectedEdge> pieces =
        ProjectVisibleEdges(s.model, occlusion, CamFromWorld(q.truth), s.camera.Undistorted());
    if (clutter >= 0) {
      q.lines = renderer.Lines(q.truth, i);
    } else {
      for (const ProjectedEdge& p : pieces) {
        if (p.image.Length() >= 20.0) q.lines.push_back(p.image);
      }
    }
    q.true_ids = TrueCorrespondences(pieces, q.lines, {});
    out.push_back(std::move(q));
  }
  return out;
}

double PoseDistance(const RobotPose& a, const RobotPose& b, const ViewGrid& grid) {
  return std::hypot(a.x - b.x, a.y - b.y) / grid.step +
         std::abs(WrapAngle(a.heading - b.heading)) / grid.heading_step;
}

std::string QueryKind(int clutter) {
  return clutter < 0 ? "exact edge pieces"
                     : "rendered, " + std::to_string(clutter) + " clutter objects";
}

bool Near(const RobotPose& a, const RobotPose& b, const ViewGrid& grid) {
  return std::hypot(a.x - b.x, a.y - b.y) <= grid.step + 1e-9 &&
         std::abs(WrapAngle(a.heading - b.heading)) <= grid.heading_step + 1e-9;
}

std::string RetrievalRow(const std::vector<Query>& queries, const ViewDatabase& db,
                         const ViewGrid& grid, int clutter) {
  int nearest_first = 0, recall[3] = {0, 0, 0}, pairs = 0, true_pairs = 0, none = 0;
  const int ks[3] = {1, 5, 10};
  std::vector<double> ms;
  for (const Query& q : queries) {
    const auto start = std::chrono::steady_clock::now();
    const std::vector<RetrievedView> ranked = RetrieveViews(q.lines, db, {});
    ms.push_back(MillisecondsSince(start));
    if (ranked.empty()) {
      ++none;
      continue;
    }
    int nearest = 0;
    for (size_t v = 1; v < db.views.size(); ++v) {
      if (PoseDistance(db.views[v].pose, q.truth, grid) <
          PoseDistance(db.views[nearest].pose, q.truth, grid)) {
        nearest = static_cast<int>(v);
      }
    }
    nearest_first += ranked.front().view == nearest;
    for (int k = 0; k < 3; ++k) {
      const int n = std::min<int>(ks[k], ranked.size());
      recall[k] += std::any_of(ranked.begin(), ranked.begin() + n, [&](const RetrievedView& r) {
        return Near(db.views[r.view].pose, q.truth, grid);
      });
    }
    for (const TransferredPair& p : ranked.front().pairs) {
      if (p.line_id < 0) continue;
      ++pairs;
      const std::vector<int>& ids = q.true_ids[p.line];
      true_pairs += std::find(ids.begin(), ids.end(), p.line_id) != ids.end();
    }
  }
  const double n = std::max<size_t>(1, queries.size());
  std::ostringstream row;
  row << std::fixed << std::setprecision(1) << "| " << QueryKind(clutter) << " | " << queries.size()
      << " | " << 100.0 * nearest_first / n << " % | " << 100.0 * recall[0] / n << " % | "
      << 100.0 * recall[1] / n << " % | " << 100.0 * recall[2] / n << " % | " << none << " | "
      << true_pairs << " / " << pairs << " (" << 100.0 * true_pairs / std::max(1, pairs) << " %) | "
      << std::setprecision(0) << QuantileNearestRank(ms, 0.5) << " / "
      << QuantileNearestRank(ms, 0.99) << " |\n";
  return row.str();
}

std::string PositioningRow(const std::vector<Query>& queries, const ViewDatabase& db, int clutter) {
  int found = 0, valid = 0;
  std::vector<double> error_all, error_valid, heading_valid, ms;
  for (const Query& q : queries) {
    const auto start = std::chrono::steady_clock::now();
    const ViewPositioning r = LocalizeFromViews(q.lines, db, {});
    ms.push_back(MillisecondsSince(start));
    if (!r.found) continue;
    ++found;
    const double e = std::hypot(r.pose.x - q.truth.x, r.pose.y - q.truth.y);
    error_all.push_back(e);
    if (!r.Valid()) continue;
    ++valid;
    error_valid.push_back(e);
    heading_valid.push_back(std::abs(RadToDeg(WrapAngle(r.pose.heading - q.truth.heading))));
  }
  std::ostringstream row;
  row << std::fixed << std::setprecision(2) << "| " << QueryKind(clutter) << " | " << queries.size()
      << " | " << found << " | " << QuantileNearestRank(error_all, 0.5) << " / "
      << QuantileNearestRank(error_all, 0.9) << " | " << valid << " | "
      << QuantileNearestRank(error_valid, 0.5) << " / " << QuantileNearestRank(error_valid, 0.9)
      << " | " << QuantileNearestRank(heading_valid, 0.5) << " | " << std::setprecision(0)
      << QuantileNearestRank(ms, 0.5) << " |\n";
  return row.str();
}

// (3): 20 points in a box `distance` ahead of model view 1, `depth` metres deep and half the
// distance wide (the paper camera's field of view), 0.3 of it tall; model view 2 turned 15 deg
// about the box's centre, the new view -5 to 25 deg and 0.7-1.3 x the distance (between the
// model views and beyond them). Exact perspective.
struct SweepCell {
  std::vector<double> error_m;
  int check_passed = 0, trials = 0;
};

std::vector<Eigen::Vector2d> Perspective(const std::vector<Eigen::Vector3d>& x,
                                         const Eigen::Matrix3d& r, const Eigen::Vector3d& c) {
  std::vector<Eigen::Vector2d> out;
  for (const Eigen::Vector3d& p : x) {
    const Eigen::Vector3d q = r * (p - c);
    out.push_back(q.head<2>() / q.z());
  }
  return out;
}

SweepCell Sweep(double distance, double depth, uint64_t seed) {
  SweepCell cell;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const Eigen::Vector3d centre(0.0, 0.0, distance);
  // A camera turned by `turn` about the vertical through the box's centre, `range` from it.
  auto camera = [&](double turn, double range) {
    const Eigen::Matrix3d r =
        CamFromWorldRotation(turn, 0.0) * CamFromWorldRotation(0.0, 0.0).transpose();
    return std::make_pair(r,
                          Eigen::Vector3d(centre - r.transpose() * Eigen::Vector3d(0, 0, range)));
  };
  const ViewPositioningOptions checks;
  for (int t = 0; t < 20; ++t) {
    std::vector<Eigen::Vector3d> x;
    for (int i = 0; i < 20; ++i) {
      x.push_back(centre + Eigen::Vector3d(0.25 * distance * unit(rng), 0.15 * distance * unit(rng),
                                           0.5 * depth * unit(rng)));
    }
    const auto [r2, c2] = camera(DegToRad(15.0), distance);
    const auto [rn, cn] =
        camera(DegToRad(10.0 + 15.0 * unit(rng)), distance * (1.0 + 0.3 * unit(rng)));
    const auto v1 = Perspective(x, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero());
    const auto v2 = Perspective(x, r2, c2), vn = Perspective(x, rn, cn);
    std::vector<double> x2;
    for (const Eigen::Vector2d& p : v2)
      x2.push_back(p.x());
    ++cell.trials;
    const auto z0 = MeanTriangulatedDepth(v1, v2, r2, c2);
    const auto w2 = z0 ? WeakPerspectiveOf(r2, c2, *z0) : std::nullopt;
    const auto combination = FitViewCombination(v1, x2, vn);
    if (!w2 || !combination) continue;
    const NovelView novel = RecoverNovelView(*combination, *w2, *z0);
    cell.error_m.push_back((novel.centre - cn).norm());
    const double scale = 0.5 * (novel.scale_a + novel.scale_b);
    cell.check_passed +=
        std::abs(novel.scale_a - novel.scale_b) / scale <= checks.max_scale_mismatch &&
        std::abs(novel.orthogonality) <= checks.max_orthogonality;
  }
  return cell;
}

std::string SweepTable() {
  const double distances[] = {2.0, 4.0, 8.0, 16.0, 32.0};
  const double depths[] = {0.5, 1.0, 2.0, 4.0, 8.0};
  std::ostringstream t;
  t << "\n(3) Weak perspective alone, exact perspective projections: 20 points in a box ahead "
       "of model view 1, half the distance wide (the paper camera's field of view) and 0.3 of "
       "it tall, `depth` deep; model view 2 turned 15 deg about the box's centre; the new view "
       "turned -5 to 25 deg, 0.7-1.3 x the distance. 20 trials a cell: median position error "
       "(metres) and the share passing the weak-perspective check.\n\n| distance (m) |";
  for (double d : depths)
    t << " depth " << d << " m |";
  t << "\n| --- |";
  for (size_t i = 0; i < std::size(depths); ++i)
    t << " --- |";
  t << "\n";
  uint64_t seed = 1;
  for (double z : distances) {
    t << "| " << z << " |";
    for (double d : depths) {
      if (d >= 1.5 * z) {
        t << " - |";
        continue;
      }
      const SweepCell c = Sweep(z, d, seed++);
      t << std::fixed << std::setprecision(2) << " " << QuantileNearestRank(c.error_m, 0.5)
        << " m, " << std::setprecision(0) << 100.0 * c.check_passed / std::max(1, c.trials)
        << " % |";
    }
    t << "\n";
  }
  return t.str();
}

int RunBenchViews(const BenchViewsOptions& opt) {
  cv::setNumThreads(1);
  Setup s{LoadModel(opt.model_path), NavigableArea(), PaperSyntheticCamera(), {}};
  s.area = NavigableArea::FromModel(s.model);
  if (!opt.camera_path.empty()) s.camera = ReadCameraXml(opt.camera_path);
  if (s.camera.width <= 0)
    throw InputError(opt.camera_path + ": the camera file gives no image size");
  const std::vector<double> g = ParseNumbers(opt.grid, 2, "--grid");
  s.grid = {g[0], DegToRad(g[1]), opt.height, DegToRad(opt.tilt_deg)};
  std::string why;
  if (!s.grid.Check(&why)) throw InputError("--grid/--height/--tilt: " + why);
  const auto start = std::chrono::steady_clock::now();
  const ViewDatabase db = BuildDatabase(s, opt);
  spdlog::info("{} key views built in {:.1f} s", db.views.size(),
               MillisecondsSince(start) / 1000.0);
  std::ostringstream t;
  t << db.views.size() << " key views of " << opt.model_path << " ("
    << (opt.render_db ? "rendered, detected lines" : "projected edges") << ", grid " << opt.grid
    << ", height " << opt.height << " m, tilt " << opt.tilt_deg << " deg, "
    << (opt.camera_path.empty() ? "the paper's camera" : opt.camera_path) << "); " << opt.count
    << " rendered queries at random positions and headings (same height and tilt, seed " << opt.seed
    << "), lines detected with FLD.\n\n(1) Retrieval. Nearest: the stored view "
       "minimising |dp| / step + |dh| / heading step. Recall@k: a view within one step and one "
       "heading step among the first k. Pairs: line ids of the first view's matched tokens "
       "that are true.\n\n"
    << "| queries | count | nearest first | recall@1 | recall@5 | recall@10 | none "
       "ranked | true pairs | ms (median / p99) |\n| --- | --- | --- | --- | --- | --- | --- | "
       "--- | --- |\n";
  std::ostringstream positioning;
  positioning << "\n(2) Positioning from two stored views (no model): found, position error "
                 "(median / p90, metres), and among the answers passing the weak-perspective "
                 "check and the robot's plausibility (roll, tilt, height).\n\n| queries | "
                 "count | found | error (m) | valid | error (m) | heading error (deg) | ms "
                 "(median) |\n| --- | --- | --- | --- | --- | --- | --- | --- |\n";
  for (int clutter : {-1, 0, opt.clutter}) {
    const std::vector<Query> queries = RenderQueries(s, opt, clutter);
    t << RetrievalRow(queries, db, s.grid, clutter);
    positioning << PositioningRow(queries, db, clutter);
  }
  t << positioning.str() << SweepTable();
  std::cout << t.str();
  if (!opt.out_path.empty()) WriteFileAtomically(opt.out_path, t.str());
  return kExitOk;
}

}  // namespace

void AddBenchViews(CLI::App& cli, CommandAction* action) {
  auto opt = std::make_shared<BenchViewsOptions>();
  CLI::App* cmd = BenchGroup(cli)->add_subcommand(
      "views",
      "Key-view retrieval, positioning from two views, and where weak perspective "
      "breaks down (docs/views.md)");
  cmd->add_option("--model", opt->model_path, "Model")->capture_default_str();
  cmd->add_option("--camera", opt->camera_path,
                  "Camera XML (default: the paper's 640x480, px = 1000)");
  cmd->add_option("--grid", opt->grid, "STEP_M,HEADING_STEP_DEG of the database")
      ->capture_default_str();
  cmd->add_option("--height", opt->height, "Camera height (metres)")->capture_default_str();
  cmd->add_option("--tilt", opt->tilt_deg, "Camera tilt (degrees)")->capture_default_str();
  cmd->add_option("--count", opt->count, "Rendered queries per clutter setting")
      ->capture_default_str();
  cmd->add_option("--seed", opt->seed, "Seed of the queries")->capture_default_str();
  cmd->add_option("--clutter", opt->clutter, "Unmodelled objects of the cluttered row")
      ->capture_default_str();
  cmd->add_flag("--render-db", opt->render_db,
                "Key views from rendered images (views build --render) instead of projections");
  cmd->add_option("--out", opt->out_path, "Also write the tables (Markdown) to this file");
  cmd->callback([opt, action] {
    if (opt->count < 1 || opt->clutter < 0)
      throw CLI::ValidationError("--count >= 1, --clutter >= 0");
    *action = [opt] { return RunBenchViews(*opt); };
  });
}

}  // namespace linetrack::app
