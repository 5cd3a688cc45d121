// Placeholder until the view-invariant-region work lands (see issue 2).
#include "models/view_invariant_regions.h"

namespace linetrack {
ViewInvariantRegions ViewInvariantRegions::Build(const WireframeModel&, const NavigableArea&,
                                                 const ViewInvariantRegionsOptions&) {
  return {};
}
}  // namespace linetrack
namespace linetrack {
std::vector<int> ViewInvariantRegions::Query(const VisibilityQuery&) const {
  return {};
}
double BearingHalfWidth(const CameraIntrinsics&, double, double) {
  return kPi;
}
}  // namespace linetrack
