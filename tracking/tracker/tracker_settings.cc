#include "tracking/tracker/tracker_settings.h"

#include <visp3/core/vpException.h>
#include <visp3/mbt/vpMbtXmlGenericParser.h>
#include <visp3/me/vpMe.h>

#include <cmath>
#include <filesystem>

#include "models/errors.h"

namespace linetrack {

bool MovingEdgeSettings::Check(std::string* why) const {
  if (mask_size < 3 || mask_size > 31 || mask_size % 2 == 0) {
    *why = "ecm mask size must be odd, in [3, 31]";
    return false;
  }
  if (mask_count < 2 || mask_count > 360) {
    *why = "ecm number of masks must be in [2, 360]";
    return false;
  }
  if (range < 1 || range > 100) {
    *why = "ecm tracking range must be in [1, 100] pixels";
    return false;
  }
  if (!(threshold > 0.0 && std::isfinite(threshold))) {
    *why = "ecm contrast threshold must be positive";
    return false;
  }
  if (!(mu1 >= 0.0 && mu1 <= 1.0) || !(mu2 >= 0.0 && mu2 <= 10.0)) {
    *why = "ecm mu1 must be in [0, 1] and mu2 in [0, 10]";
    return false;
  }
  if (!(sample_step >= 1.0 && sample_step <= 100.0)) {
    *why = "ecm sample step must be in [1, 100] pixels";
    return false;
  }
  return true;
}

bool VisibilitySettings::Check(std::string* why) const {
  if (!(angle_appear_deg > 0.0 && angle_appear_deg <= 90.0) ||
      !(angle_disappear_deg > 0.0 && angle_disappear_deg <= 90.0)) {
    *why = "face angles must be in (0, 90] degrees";
    return false;
  }
  if (!(near_clipping_m >= 0.0 && far_clipping_m > near_clipping_m &&
        std::isfinite(far_clipping_m))) {
    *why = "face clipping distances must satisfy 0 <= near < far (metres)";
    return false;
  }
  return true;
}

bool TrackerSettings::Check(std::string* why) const {
  if (!me.Check(why) || !visibility.Check(why) || !refinement.Check(why) || !alignment.Check(why)) {
    return false;
  }
  if (passes < 1 || passes > 10) {
    *why = "passes must be in [1, 10]";
    return false;
  }
  if (!(pass_step_factor >= 1.0 && pass_step_factor <= 10.0)) {
    *why = "pass step factor must be in [1, 10]";
    return false;
  }
  if (max_iterations < 1 || max_iterations > 1000) {
    *why = "max_iterations must be in [1, 1000]";
    return false;
  }
  if (first_passes_max_iterations < 0 || first_passes_max_iterations > 1000) {
    *why = "first_passes_max_iterations must be in [0, 1000] (0: max_iterations)";
    return false;
  }
  if (!(good_edge_ratio >= 0.0 && good_edge_ratio < 1.0)) {
    *why = "good_edge_ratio must be in [0, 1)";
    return false;
  }
  return true;
}

TrackerSettings ReadTrackerSettings(const std::string& path, const TrackerSettings& base) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw InputError(Located(path, 0, "cannot read the tracker settings file"));
  }
  TrackerSettings settings = base;
  settings.source = path;
  try {
    vpMbtXmlGenericParser parser(vpMbtXmlGenericParser::EDGE_PARSER);
    parser.setVerbose(false);
    parser.parse(path);
    vpMe me;
    parser.getEdgeMe(me);
    settings.me.mask_size = static_cast<int>(me.getMaskSize());
    settings.me.mask_count = static_cast<int>(me.getMaskNumber());
    settings.me.range = static_cast<int>(me.getRange());
    settings.me.threshold = me.getThreshold();
    settings.me.mu1 = me.getMu1();
    settings.me.mu2 = me.getMu2();
    settings.me.sample_step = me.getSampleStep();
    settings.visibility.angle_appear_deg = parser.getAngleAppear();
    settings.visibility.angle_disappear_deg = parser.getAngleDisappear();
    if (parser.hasNearClippingDistance())
      settings.visibility.near_clipping_m = parser.getNearClippingDistance();
    if (parser.hasFarClippingDistance())
      settings.visibility.far_clipping_m = parser.getFarClippingDistance();
    settings.visibility.fov_clipping = parser.getFovClipping();
  } catch (const vpException&) {
    // ViSP reports malformed XML as "Cannot open file".
    throw InputError(Located(path, 0, "not a readable ViSP tracker XML file (malformed XML?)"));
  }
  std::string why;
  if (!settings.Check(&why)) throw InputError(Located(path, 0, why));
  return settings;
}

}  // namespace linetrack
