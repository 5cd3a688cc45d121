// Placeholder until the navigable-area work lands (see issue 2).
#include "models/navigable_area.h"

#include "models/errors.h"

namespace linetrack {
NavigableArea NavigableArea::FromModel(const WireframeModel& model, const NavigableAreaOptions&) {
  throw InputError(model.path() + ": navigable area not implemented yet");
}
double NavigableArea::Area() const {
  return 0.0;
}
}  // namespace linetrack
