// Placeholder until the view-invariant-region work lands (see issue 2).
#include "models/view_invariant_regions.h"

namespace linetrack {
ViewInvariantRegions ViewInvariantRegions::Build(const WireframeModel&, const NavigableArea&,
                                                 const ViewInvariantRegionsOptions&) {
  return {};
}
}  // namespace linetrack
