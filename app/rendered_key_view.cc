#include "app/rendered_key_view.h"

#include <algorithm>
#include <set>

#include "matching/evaluation/line_evaluation.h"

namespace linetrack::app {
namespace {

RenderOptions SceneOptions(const KeyViewRenderOptions& options) {
  RenderOptions render;
  render.scene.seed = options.seed;
  render.scene.clutter = options.clutter;
  return render;
}

}  // namespace

KeyViewRenderer::KeyViewRenderer(const WireframeModel& model, const NavigableArea& area,
                                 const CameraIntrinsics& camera,
                                 const KeyViewRenderOptions& options)
    : model_(model),
      renderer_(model, camera, SceneOptions(options), &area),
      extractor_(options.lines, camera) {}

std::vector<Segment2> KeyViewRenderer::Lines(const RobotPose& pose, int frame) {
  return extractor_(renderer_.Render(CamFromWorld(pose), frame));
}

KeyView KeyViewRenderer::Render(const std::vector<ProjectedEdge>& pieces, const RobotPose& pose,
                                int frame) {
  KeyView view;
  view.pose = pose;
  const std::vector<Segment2> lines = Lines(pose, frame);
  const std::vector<std::vector<int>> ids = TrueCorrespondences(pieces, lines, {});
  std::set<int> seen;
  for (size_t i = 0; i < lines.size(); ++i) {
    // A line along collinear edges takes the first; their junctions need not be resolved.
    const int id = ids[i].empty() ? -1 : ids[i].front();
    view.segments.push_back({lines[i], id});
    if (id >= 0) seen.insert(id);
  }
  for (ViewJunction j : VertexJunctions(model_, pieces, {})) {
    j.lines.erase(
        std::remove_if(j.lines.begin(), j.lines.end(), [&](int id) { return seen.count(id) == 0; }),
        j.lines.end());
    if (j.lines.size() >= 2) view.junctions.push_back(j);
  }
  return view;
}

}  // namespace linetrack::app
