// `linetrack bench building`: the generated office building (models/synth/synthetic_building.h)
// against each of its rooms modelled alone: the regions' build time and memory, localisation
// per room under the paper's priors (QI1-3), and the localize median of both.
#include <sys/resource.h>
#include <time.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "app/commands.h"
#include "app/match_outcome.h"
#include "matching/evaluation/diagnosis.h"
#include "matching/localizer.h"
#include "models/navigable_area.h"
#include "models/statistics.h"
#include "models/synth/synthetic_building.h"
#include "models/synth/synthetic_scenes.h"
#include "models/view_invariant_regions.h"

namespace linetrack::app {
namespace {

using Clock = std::chrono::steady_clock;

struct BenchBuildingOptions {
  BuildingSpec spec;
  int count = 100;  // scenes per room and prior
  uint64_t seed = 1;
  int max_rooms = 0;              // 0: every room
  std::string localize = "both";  // which models localise: "both", "building" or "alone"
  std::string out_path;
  std::string regions_path;  // every region of the building, to compare two builds
  std::string scenes_path;   // one JSON line per localisation, for the analysis of the table
  int regions_threads = 0;   // ViewInvariantRegionsOptions::threads of the building's regions
  // Localise the same lines with both models: the scenes drawn in the building whose view sees
  // nothing through the door (false: each model draws its own scenes).
  bool paired = false;
};

double MsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// CPU time of the process (all its threads, user + system), seconds.
double ProcessCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

double MaxRssMb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024.0;  // kilobytes on Linux
}

// A model with its area, regions and localizer.
struct Setup {
  std::unique_ptr<WireframeModel> model;
  std::unique_ptr<NavigableArea> area;
  std::unique_ptr<ViewInvariantRegions> regions;
  std::unique_ptr<Localizer> localizer;
  double regions_ms = 0.0;
  double regions_cpu_ms = 0.0;  // CPU time of the build, all threads
};

Setup Prepare(const CaoModel& cao, const CameraIntrinsics& camera, int regions_threads) {
  Setup s;
  s.model = std::make_unique<WireframeModel>(WireframeModel::FromCao(cao));
  s.area = std::make_unique<NavigableArea>(NavigableArea::FromModel(*s.model));
  const Clock::time_point start = Clock::now();
  const double cpu_start = ProcessCpuSeconds();
  ViewInvariantRegionsOptions options;
  options.threads = regions_threads;
  s.regions = std::make_unique<ViewInvariantRegions>(
      ViewInvariantRegions::Build(*s.model, *s.area, options));
  s.regions_cpu_ms = 1e3 * (ProcessCpuSeconds() - cpu_start);
  s.regions_ms = MsSince(start);
  s.localizer = std::make_unique<Localizer>(*s.model, s.regions.get(), s.area.get(), camera);
  return s;
}

// The localize times (milliseconds) and candidate edges of a series of scenes, and one JSON
// object per localisation when `scenes` is set.
struct LocalizeCosts {
  std::vector<double> times;
  std::vector<double> candidates;
  std::ostream* scenes = nullptr;
};

// What a series of scenes is, for the per-scene lines: the room (its free rectangle, metres),
// the prior's quality index, and which model ("building" or "alone").
struct SeriesLabel {
  const BuildingSpace* room = nullptr;
  int qi = 0;
  const char* model = "";
};

// How far past a room's free rectangle its own edges reach (metres): the wall (0.2 m), the door's
// leaf on its far side and the casing.
constexpr double kWallMargin = 0.35;

// Candidate edges of `ids` with no end within the room's rectangle grown by `margin` (metres):
// edges of other spaces, seen through the door.
int ForeignEdges(const WireframeModel& model, const std::vector<int>& ids,
                 const BuildingSpace& room, double margin) {
  const auto inside = [&](const Eigen::Vector3d& p) {
    return p.x() >= room.lo.x() - margin && p.x() <= room.hi.x() + margin &&
           p.y() >= room.lo.y() - margin && p.y() <= room.hi.y() + margin;
  };
  int foreign = 0;
  for (int id : ids) {
    const Segment3& s = model.edges()[id].segment;
    foreign += inside(s.a) || inside(s.b) ? 0 : 1;
  }
  return foreign;
}

// For each edge of `from`, the edge of `to` with the same segment (either direction, within
// 1 mm), or -1: the models of a room alone and of the building share world coordinates.
std::vector<int> SameEdges(const WireframeModel& from, const WireframeModel& to) {
  constexpr double kSameM = 1e-3;
  const auto same = [](const Segment3& s, const Segment3& t) {
    return ((s.a - t.a).norm() < kSameM && (s.b - t.b).norm() < kSameM) ||
           ((s.a - t.b).norm() < kSameM && (s.b - t.a).norm() < kSameM);
  };
  std::vector<int> map(from.edges().size(), -1);
  for (size_t i = 0; i < from.edges().size(); ++i) {
    for (const ModelEdge& e : to.edges()) {
      if (same(from.edges()[i].segment, e.segment)) map[i] = e.id;
    }
  }
  return map;
}

// True when every model line of `scene` images an edge that the other model has too (`map`,
// from SameEdges): the view sees nothing through the door, so the room alone can explain the
// same lines. `moved` gets the scene with its correspondences in the other model's edge ids.
bool SameImageInOtherModel(const SyntheticScene& scene, const std::vector<int>& map,
                           SyntheticScene* moved) {
  *moved = scene;
  for (auto& match : moved->matches) {
    if (map[match.first] < 0) return false;
    match.first = map[match.first];
  }
  std::sort(moved->matches.begin(), moved->matches.end());
  return true;
}

// One localisation's line for --scenes-out; a wrong answer also gets the truth's own
// verification (DiagnoseTruth): was the truth plausible, and with what evidence (nats)?
nlohmann::ordered_json SceneRow(const Setup& setup, const SyntheticScene& scene,
                                const LocalizationProblem& problem,
                                const LocalizationResult& result, MatchOutcome outcome,
                                const SeriesLabel& label, double ms) {
  nlohmann::ordered_json row = {
      {"room", label.room->name},
      {"qi", label.qi},
      {"model", label.model},
      {"scene", scene.index},
      {"lines", scene.lines.size()},
      {"prior", {scene.prior.x, scene.prior.y, RadToDeg(scene.prior.heading)}},
      {"delta_t", scene.delta_t},
      {"truth", {scene.truth.x, scene.truth.y, RadToDeg(scene.truth.heading)}},
      {"candidates", result.candidate_edges},
      {"foreign", ForeignEdges(*setup.model, setup.localizer->CandidateEdges(problem), *label.room,
                               kWallMargin)},
      {"tree_nodes", result.tree_nodes},
      {"tree_checks", result.tree_checks},
      {"hypotheses", result.hypotheses},
      {"exhausted", result.budget_exhausted},
      {"completed_bound", result.tree_completed_bound},
      {"unexplained_bound", result.unexplained_completed_bound},
      {"score", result.finalists.empty() ? 0.0 : result.finalists.front().evidence.Score()},
      {"support", result.support},
      {"matched", result.finalists.empty() ? 0 : result.finalists.front().matched_edges},
      {"reported", result.matches.size()},
      {"finalists", result.finalists.size()},
      {"outcome", MatchOutcomeName(outcome)},
      {"answer", result.found ? nlohmann::ordered_json{result.pose.x, result.pose.y,
                                                       RadToDeg(result.pose.heading)}
                              : nlohmann::ordered_json()},
      {"reason", result.reason},
      {"ms", ms}};
  if (outcome == MatchOutcome::kWrong) {
    const TruthDiagnosis truth =
        DiagnoseTruth(*setup.localizer, problem, scene.truth.Planar(), scene.matches);
    row["truth_plausible"] = truth.plausible;
    row["truth_evidence"] = truth.evidence_score;
    row["truth_why"] = truth.implausible_because;
  }
  return row;
}

// Correct answers of `scenes` localised by `setup`, their costs appended to `costs`.
int CorrectAnswers(const Setup& setup, const std::vector<SyntheticScene>& scenes,
                   const SeriesLabel& label, LocalizeCosts* costs) {
  int correct = 0;
  for (const SyntheticScene& scene : scenes) {
    const LocalizationProblem problem = ProblemOf(scene);
    const Clock::time_point start = Clock::now();
    const LocalizationResult result = setup.localizer->Localize(problem);
    costs->times.push_back(MsSince(start));
    costs->candidates.push_back(result.candidate_edges);
    const MatchOutcome outcome = JudgeScene(scene, result);
    correct += outcome == MatchOutcome::kCorrect ? 1 : 0;
    if (costs->scenes == nullptr) continue;
    *costs->scenes
        << SceneRow(setup, scene, problem, result, outcome, label, costs->times.back()).dump()
        << '\n';
  }
  return correct;
}

// The room's own navigable area (its model alone's), standing on `storey` of the building.
NavigableArea RoomArea(const NavigableArea& alone, int storey, const std::vector<Storey>& storeys) {
  std::vector<AreaPart> parts = alone.parts();
  for (AreaPart& part : parts)
    part.storey = storey;
  std::vector<std::vector<Segment2>> walls(storeys.size());
  walls[storey] = alone.walls();
  return NavigableArea::FromParts(std::move(parts), std::move(walls), storeys, alone.clearance(),
                                  alone.source());
}

// Every region of `regions`: its storey, polygon and list (edge id, all bearings, diamond arc),
// numbers to 17 digits, one region a line.
std::string RegionsText(const ViewInvariantRegions& regions) {
  std::ostringstream out;
  out.precision(17);
  for (const ViewRegion& region : regions.regions()) {
    out << "storey " << region.storey << " polygon";
    for (const Eigen::Vector2d& p : region.polygon.vertices)
      out << ' ' << p.x() << ' ' << p.y();
    out << " visible";
    for (const RegionEdge& e : region.visible)
      out << ' ' << e.edge_id << ' ' << e.all_bearings << ' ' << e.diamond_min << ' '
          << e.diamond_max;
    out << '\n';
  }
  return out.str();
}

// What the table's counts are out of.
std::string Caption(const BenchBuildingOptions& opt, int scenes_per_model, int drawn) {
  if (!opt.paired) {
    return "correct of " + std::to_string(opt.count) + " scenes per room and prior";
  }
  return "correct of the scenes drawn in the building whose view sees nothing through the door (" +
         std::to_string(scenes_per_model) + " of " + std::to_string(drawn) + " drawn, " +
         std::to_string(opt.count) + " per room and prior), the same lines for both models";
}

int RunBenchBuilding(const BenchBuildingOptions& opt) {
  const CameraIntrinsics camera = PaperSyntheticCamera();
  const SyntheticBuilding building = GenerateBuilding(opt.spec);
  const double rss_before = MaxRssMb();
  const Setup whole = Prepare(building.cao, camera, opt.regions_threads);
  const double rss_after = MaxRssMb();
  if (!opt.regions_path.empty()) WriteFileAtomically(opt.regions_path, RegionsText(*whole.regions));
  std::ostringstream out;
  char line[512];
  int rooms = 0;
  for (const BuildingSpace& space : building.spaces)
    rooms += space.corridor ? 0 : 1;
  std::snprintf(
      line, sizeof(line),
      "building: %d storeys, %d rooms, %zu edges, %zu faces; navigable area %.1f m2 in "
      "%zu parts\nregions: %d built in %.0f ms (CPU %.0f ms, all threads), peak memory +%.0f MB "
      "(process %.0f MB)\n\n",
      opt.spec.storeys, rooms, whole.model->edges().size(), whole.model->faces().size(),
      whole.area->Area(), whole.area->parts().size(), whole.regions->size(), whole.regions_ms,
      whole.regions_cpu_ms, std::max(0.0, rss_after - rss_before), rss_after);
  out << line
      << "| room | QI1 building | QI1 alone | QI2 building | QI2 alone | QI3 building | "
         "QI3 alone |\n| --- | --- | --- | --- | --- | --- | --- |\n";
  LocalizeCosts building_costs, alone_costs;
  std::ostringstream scenes;
  if (!opt.scenes_path.empty()) building_costs.scenes = alone_costs.scenes = &scenes;
  std::array<int, 3> sum_building{}, sum_alone{};
  int done = 0, scenes_per_model = 0;
  for (size_t k = 0; k < building.spaces.size(); ++k) {
    const BuildingSpace& room = building.spaces[k];
    if (room.corridor || (opt.max_rooms > 0 && done >= opt.max_rooms)) continue;
    ++done;
    const Setup alone =
        Prepare(SpaceAlone(opt.spec, static_cast<int>(k)), camera, opt.regions_threads);
    const NavigableArea sampling = RoomArea(*alone.area, room.storey, whole.model->storeys());
    const std::vector<int> alone_edges =
        opt.paired ? SameEdges(*whole.model, *alone.model) : std::vector<int>{};
    out << "| " << room.name;
    for (int qi = 1; qi <= 3; ++qi) {
      SyntheticSceneOptions o;
      o.seed = opt.seed + 1000 * k;
      o.count = opt.count;
      const PriorBounds bounds = QualityIndexBounds(qi);
      o.delta_t = bounds.delta_t;
      o.delta_phi = bounds.delta_phi;
      o.floor_z = room.floor_z;
      o.storey = room.storey;
      // Each model's scenes: drawn in it, or (paired) the building's whose view sees nothing
      // through the door, in both. One model only localises for a profiler that counts a
      // model's localisations alone.
      std::vector<SyntheticScene> in_building = opt.localize == "alone" && !opt.paired
                                                    ? std::vector<SyntheticScene>{}
                                                    : GenerateScenes(*whole.model, sampling, o);
      std::vector<SyntheticScene> in_alone;
      if (opt.paired) {
        std::vector<SyntheticScene> kept;
        for (const SyntheticScene& scene : in_building) {
          SyntheticScene moved;
          if (!SameImageInOtherModel(scene, alone_edges, &moved)) continue;
          kept.push_back(scene);
          in_alone.push_back(std::move(moved));
        }
        in_building = std::move(kept);
      } else if (opt.localize != "building") {
        o.storey = 0;
        in_alone = GenerateScenes(*alone.model, *alone.area, o);
      }
      scenes_per_model += static_cast<int>(std::max(in_building.size(), in_alone.size()));
      const int b =
          opt.localize == "alone"
              ? 0
              : CorrectAnswers(whole, in_building, {&room, qi, "building"}, &building_costs);
      const int a = opt.localize == "building"
                        ? 0
                        : CorrectAnswers(alone, in_alone, {&room, qi, "alone"}, &alone_costs);
      sum_building[qi - 1] += b;
      sum_alone[qi - 1] += a;
      out << " | " << b << " | " << a;
    }
    out << " |\n";
    std::cerr << "\rrooms " << done << std::flush;
  }
  std::cerr << "\n";
  out << "| **all** ";
  for (int qi = 0; qi < 3; ++qi)
    out << "| **" << sum_building[qi] << "** | **" << sum_alone[qi] << "** ";
  const double t_building = Median(building_costs.times), t_alone = Median(alone_costs.times);
  std::snprintf(line, sizeof(line),
                "|\n\n%s (seed %llu)\nlocalize median: "
                "building %.3f ms, rooms alone %.3f ms (x %.2f)\ncandidate edges median: "
                "building %.0f, rooms alone %.0f\n",
                Caption(opt, scenes_per_model, 3 * done * opt.count).c_str(),
                static_cast<unsigned long long>(opt.seed), t_building, t_alone,
                t_building / std::max(1e-9, t_alone), Median(building_costs.candidates),
                Median(alone_costs.candidates));
  out << line;
  std::cout << out.str();
  if (!opt.out_path.empty()) WriteFileAtomically(opt.out_path, out.str());
  if (!opt.scenes_path.empty()) WriteFileAtomically(opt.scenes_path, scenes.str());
  return kExitOk;
}

}  // namespace

void AddBenchBuilding(CLI::App& cli, CommandAction* action) {
  auto opt = std::make_shared<BenchBuildingOptions>();
  CLI::App* cmd = BenchGroup(cli)->add_subcommand(
      "building",
      "The generated office building against its rooms modelled alone: regions' build time and "
      "memory, correct localisations per room under the paper's priors, localize medians");
  cmd->add_option("--storeys", opt->spec.storeys, "Storeys")->capture_default_str();
  cmd->add_option("--rooms-per-side", opt->spec.rooms_per_side, "Rooms per corridor side")
      ->capture_default_str();
  cmd->add_option("--count", opt->count, "Scenes per room and prior")->capture_default_str();
  cmd->add_option("--seed", opt->seed, "Seed of the scenes")->capture_default_str();
  cmd->add_option("--rooms", opt->max_rooms, "Only the first N rooms (0: all)")
      ->capture_default_str();
  cmd->add_option("--localize", opt->localize,
                  "Which models localise the scenes (the other's columns are 0): both, building or "
                  "alone")
      ->check(CLI::IsMember({"both", "building", "alone"}))
      ->capture_default_str();
  cmd->add_flag("--paired", opt->paired,
                "Localise the same lines with both models: the scenes drawn in the building whose "
                "view sees nothing through the door (default: each model draws its own scenes)");
  cmd->add_option("--out", opt->out_path, "Also write the table (Markdown) to this file");
  cmd->add_option("--regions-threads", opt->regions_threads,
                  "Threads building the regions' lists (0: one per hardware thread)")
      ->capture_default_str();
  cmd->add_option("--regions-out", opt->regions_path,
                  "Write every region of the building (storey, polygon, list) to this file, to "
                  "compare two builds");
  cmd->add_option("--scenes-out", opt->scenes_path,
                  "Write one JSON line per localisation (room, prior, model, candidate edges and "
                  "those of other spaces, tree work, outcome, time) to this file");
  cmd->callback([opt, action] {
    if (opt->count < 1) throw CLI::ValidationError("--count", "must be at least 1");
    if (opt->regions_threads < 0 || opt->regions_threads > 256)
      throw CLI::ValidationError("--regions-threads", "must be in [0, 256]");
    *action = [opt] { return RunBenchBuilding(*opt); };
  });
}

}  // namespace linetrack::app
