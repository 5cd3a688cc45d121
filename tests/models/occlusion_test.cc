// The occlusion tester's plan grid: Blocked answers as testing every face in turn, on random
// sight segments (long, short, vertical, and ending on model edges) in generated buildings (a
// bundled model has too few faces for the grid).
#include "models/occlusion.h"

#include <gtest/gtest.h>

#include <random>

#include "models/synth/synthetic_building.h"
#include "models/wireframe.h"

namespace linetrack {
namespace {

// Segments over the model's box grown by 1 m in plan: every fourth short, every fourth ending on a
// model edge, every eighth inside one storey, every sixteenth vertical. Returns how many are
// blocked; expects Blocked to agree with BlockedByAnyFace on each.
int ExpectGridEqualsEveryFace(const WireframeModel& model, int count) {
  const OcclusionTester occlusion(model);
  std::mt19937 rng(7u);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const Eigen::Vector3d lo = model.BoxMin() - Eigen::Vector3d(1.0, 1.0, 0.0);
  const Eigen::Vector3d hi = model.BoxMax() + Eigen::Vector3d(1.0, 1.0, 0.0);
  const auto pick = [&] {
    return Eigen::Vector3d(lo.x() + u(rng) * (hi.x() - lo.x()), lo.y() + u(rng) * (hi.y() - lo.y()),
                           lo.z() + u(rng) * (hi.z() - lo.z()));
  };
  int blocked = 0;
  for (int i = 0; i < count; ++i) {
    Eigen::Vector3d a = pick();
    Eigen::Vector3d b = pick();
    if (i % 4 == 1) b = a + (b - a).normalized() * 4.0 * u(rng);
    if (i % 4 == 2) {
      const Segment3& edge = model.edges()[rng() % model.edges().size()].segment;
      b = edge.a + u(rng) * (edge.b - edge.a);
    }
    if (i % 8 == 5) {  // both ends within one storey: the walk of a single layer
      const Storey& storey = model.storeys()[(i / 8) % model.storeys().size()];
      a.z() = storey.floor_z + u(rng) * (storey.top_z - storey.floor_z);
      b.z() = storey.floor_z + u(rng) * (storey.top_z - storey.floor_z);
    }
    if (i % 16 == 3) b.head<2>() = a.head<2>();
    const bool any_face = occlusion.BlockedByAnyFace(a, b);
    EXPECT_EQ(occlusion.Blocked(a, b), any_face) << a.transpose() << " -> " << b.transpose();
    blocked += any_face ? 1 : 0;
  }
  return blocked;
}

TEST(OcclusionTester, GridAnswersAsEveryFace) {
  for (int rooms_per_side : {2, 9}) {
    SCOPED_TRACE(rooms_per_side);
    BuildingSpec spec;
    spec.rooms_per_side = rooms_per_side;
    const WireframeModel model = WireframeModel::FromCao(GenerateBuilding(spec).cao);
    ASSERT_GT(model.faces().size(), 100u);  // enough faces for the grid
    const int count = 20000;
    const int blocked = ExpectGridEqualsEveryFace(model, count);
    EXPECT_GT(blocked, count / 10);  // the segments exercise both answers
    EXPECT_LT(blocked, count - count / 10);
  }
}

}  // namespace
}  // namespace linetrack
