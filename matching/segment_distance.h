// Distances between image segments used to verify hypotheses (paper, section 3.3, eq. 9-10).
#pragma once

#include <vector>

#include "models/geometry.h"

namespace linetrack {

// Eq. 9: mean distance (pixels) from the points of the observed segment to the projected
// segment (each point to its nearest point of the projected segment), integrated exactly along
// the observed segment. Unlike the paper's 1/lambda_p normalisation this is a true mean, so a
// short fragment is not favoured.
double SegmentDistance(const Segment2& projected, const Segment2& observed);

// Eq. 10: the largest of the k smallest distances (Hausdorff-style partial distance); +inf when
// there are fewer than k distances. k >= 1.
double PartialHausdorff(std::vector<double> distances, int k);

}  // namespace linetrack
