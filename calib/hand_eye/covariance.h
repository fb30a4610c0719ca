#pragma once
// Internal to hand_eye: how far the errors of motion pairs are correlated in time, for the
// sandwich covariances of the closed form and the refinement (defined in refine.cpp).
#include <vector>

#include "rigcal/hand_eye/hand_eye.h"

namespace rigcal::hand_eye {

// The window L of the Bartlett weights over the pairs `in` (indices, in time order): twice the
// largest number of following pairs that start before or when a pair ends (pairs end to end
// share a fix: 1; pairs every 0.1 s of 1 s: 10), at most twice 128 (motions between every two
// stations of a long trajectory all overlap; their covariance is not meaningful anyway).
size_t bartlett_window(const std::vector<MotionPair>& pairs, const std::vector<size_t>& in);

}  // namespace rigcal::hand_eye
