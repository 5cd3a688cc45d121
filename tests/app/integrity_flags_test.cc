// The integrity and coasting flags of `replay`, `live` and `localize` (app/integrity_output.h):
// the options they set, and one error naming the flag for every malformed value.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "app/integrity_output.h"
#include "models/errors.h"
#include "models/geometry.h"

namespace linetrack::app {
namespace {

constexpr double kExact = 1e-12;

// The message of the InputError that `flags.Options()` throws ("" when it throws none).
template <typename Flags>
std::string ErrorOf(const Flags& flags) {
  try {
    flags.Options();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(IntegrityFlags, DefaultsAreTheMonitorsDefaults) {
  const IntegrityOptions options = IntegrityFlags().Options();
  const IntegrityOptions defaults;
  EXPECT_NEAR(options.alert_position_m, 0.10, kExact);
  EXPECT_NEAR(options.alert_rotation_rad, DegToRad(2.0), kExact);
  EXPECT_EQ(options.edge_fault_probability, defaults.edge_fault_probability);
  EXPECT_EQ(options.exclusion_risk, defaults.exclusion_risk);
  EXPECT_EQ(options.solver.noise.model_sigma_m, defaults.solver.noise.model_sigma_m);
}

TEST(IntegrityFlags, GivenValuesReachTheOptions) {
  IntegrityFlags flags;
  flags.alert_limit = "0.25,3.5";
  flags.camera_sigma = "0.01,2";
  flags.edge_fault_prior = 0.01;
  flags.exclusion_risk = 1e-3;
  flags.held_parameters = "consider,estimate";
  const IntegrityOptions options = flags.Options();
  EXPECT_NEAR(options.alert_position_m, 0.25, kExact);
  EXPECT_NEAR(options.alert_rotation_rad, DegToRad(3.5), kExact);
  EXPECT_NEAR(options.solver.considered.focal_relative, 0.01, kExact);
  EXPECT_NEAR(options.solver.considered.principal_point_px, 2.0, kExact);
  EXPECT_NEAR(options.edge_fault_probability, 0.01, kExact);
  EXPECT_NEAR(options.exclusion_risk, 1e-3, kExact);
  EXPECT_EQ(options.solver.considered.intrinsics, ConsideredUncertainty::Handling::kConsider);
  EXPECT_EQ(options.solver.considered.mount, ConsideredUncertainty::Handling::kEstimate);
}

TEST(IntegrityFlags, MalformedValuesNameTheirFlag) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  struct Case {
    void (*set)(IntegrityFlags*);
    const char* flag;
  };
  const Case cases[] = {
      {[](IntegrityFlags* f) { f->alert_limit = "0.1"; }, "--alert-limit"},
      {[](IntegrityFlags* f) { f->alert_limit = "abc,2"; }, "--alert-limit"},
      {[](IntegrityFlags* f) { f->alert_limit = "-1,2"; }, "--alert-limit"},
      {[](IntegrityFlags* f) { f->camera_sigma = "0.9,1"; }, "--camera-sigma"},
      {[](IntegrityFlags* f) { f->edge_fault_prior = 0.7; }, "--edge-fault-prior"},
      {[](IntegrityFlags* f) { f->exclusion_risk = 0.0; }, "--exclusion-risk"},
      {[](IntegrityFlags* f) { f->exclusion_risk = 0.6; }, "--exclusion-risk"},
      {[](IntegrityFlags* f) { f->held_parameters = "guess"; }, "--held-parameters"},
      {[](IntegrityFlags* f) { f->model_sigma_m = -0.01; }, "--model-sigma"},
  };
  for (const Case& c : cases) {
    IntegrityFlags flags;
    c.set(&flags);
    const std::string error = ErrorOf(flags);
    EXPECT_NE(error.find(c.flag), std::string::npos) << c.flag << ": '" << error << "'";
  }
  IntegrityFlags not_a_number;
  not_a_number.exclusion_risk = nan;
  EXPECT_NE(ErrorOf(not_a_number).find("--exclusion-risk"), std::string::npos);
}

TEST(CoastFlags, DefaultsAndGivenValues) {
  const CoastOptions defaults = CoastFlags().Options();
  EXPECT_TRUE(defaults.enabled);
  EXPECT_NEAR(defaults.bound.distance_share, 0.15, kExact);
  EXPECT_NEAR(defaults.bound.heading_per_m, DegToRad(3.0), kExact);
  EXPECT_NEAR(defaults.max_distance_m, 2.0, kExact);
  EXPECT_EQ(defaults.max_frames, 50);

  CoastFlags flags;
  flags.odometry_bound = "0.05,1,0.1";
  flags.coast_limit = "4,0";  // 0 frames: no coasting
  const CoastOptions options = flags.Options();
  EXPECT_FALSE(options.enabled);
  EXPECT_NEAR(options.bound.distance_share, 0.05, kExact);
  EXPECT_NEAR(options.bound.turn_share, 0.1, kExact);
  EXPECT_NEAR(options.max_distance_m, 4.0, kExact);
}

TEST(CoastFlags, MalformedValuesNameTheirFlag) {
  CoastFlags short_bound;
  short_bound.odometry_bound = "0.15,3";
  EXPECT_NE(ErrorOf(short_bound).find("--odometry-bound"), std::string::npos);
  CoastFlags share_of_one;
  share_of_one.odometry_bound = "1.0,3,0.15";
  EXPECT_NE(ErrorOf(share_of_one).find("--odometry-bound"), std::string::npos);
  CoastFlags negative_limit;
  negative_limit.coast_limit = "-2,50";
  EXPECT_NE(ErrorOf(negative_limit).find("--coast-limit"), std::string::npos);
}

}  // namespace
}  // namespace linetrack::app
