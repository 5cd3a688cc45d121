// The benchmark's baseline: hypothesise-and-test without the interpretation tree (RANSAC-like).
// Random pairs of (edge, line) correspondences give minimal 3-DOF poses; those inside the prior
// are verified exactly like the tree's hypotheses. It measures what the tree's constraints save.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "matching/interpretation_tree.h"
#include "matching/localizer.h"
#include "matching/verification.h"

namespace linetrack {

struct BaselineOptions {
  int max_samples = 20000;    // random pairs drawn at most
  double confidence = 0.999;  // adaptive stop: probability of having drawn one all-true pair
  uint64_t seed = 1;

  bool Check(std::string* why) const;
};

struct BaselineStats {
  int samples = 0;  // pairs drawn
  int poses = 0;    // minimal poses inside the prior, verified (pose evaluations)
};

// Draws pairs, verifies the minimal poses inside the prior (with `gate` margins on the heading
// and the disk), and returns every verified pose.
std::vector<VerifiedPose> SampleAndVerify(const VerificationContext& context,
                                          const PriorRegion& prior, const BaselineOptions& options,
                                          const VerificationOptions& verification,
                                          BaselineStats* stats);

// The baseline as the localizer's hypothesise-and-test sampler (LocalizerOptions::sampler, with
// method kHypothesizeAndTest). Throws InputError when `options` are invalid.
HypothesisSampler BaselineSampler(const BaselineOptions& options);

}  // namespace linetrack
