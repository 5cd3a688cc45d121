#include "tracking/live/pose_estimator.h"

namespace linetrack {

const char* ToString(PoseStatus status) {
  switch (status) {
    case PoseStatus::kInitialising:
      return "initialising";
    case PoseStatus::kTracking:
      return "tracking";
    case PoseStatus::kLost:
      return "lost";
    case PoseStatus::kRelocalised:
      return "relocalised";
    case PoseStatus::kCoasting:
      return "coasting";
  }
  return "unknown";
}

}  // namespace linetrack
