#pragma once
// Each motion between consecutive scans from two estimates of it, fused by covariance
// intersection (doc/ground-truth.md): the odometry's and the bundle adjustment's motions come
// from the same scans, their errors correlated by an unknown amount, and covariance
// intersection is the fusion that stays consistent whatever that correlation is. Each step's
// information is w I_a + (1 - w) I_b, w in [0, 1] chosen to make the fused covariance's
// determinant smallest, and its motion the information-weighted mean of the two in rigcal's
// tangent (types.h). Where one estimate is far better in every direction, w picks it; where
// each is better in some directions, the fusion takes each direction from the better one.
//
// It is only as good as the covariances, so they are tested first: each step's two motions must
// differ as their covariances allow (d' (C_a + C_b)^-1 d, chi-square with 6 degrees of freedom).
// When more than `max_disagreeing` of the steps lie above its 99 % quantile (1 % would, with
// honest covariances), one estimate claims more than it has and b's motions are kept alone; a
// step above its 99.99 % quantile keeps b's motion.
#include <vector>

#include "rigcal/gt/types.h"

namespace rigcal::gt {

struct FusedMotions {
  // The fused motions chained from b's first pose, with their covariances.
  OdometryInput motions;
  std::vector<double> weight_a;  // w of each step (0 where b's motion is kept)
  size_t disagreeing = 0;        // steps whose motions differ beyond the 99.99 % gate
  // The steps above the 99 % quantile, and whether the fusion was done (false: b's motions).
  double disagreeing_fraction = 0;
  bool fused = false;
};

// `a`, `b`: the same poses' stamps (throws rigcal::Error otherwise), each step's covariance
// positive definite (a step whose either one is not keeps b's).
FusedMotions fuse_motions(const OdometryInput& a, const OdometryInput& b,
                          double max_disagreeing = 0.05);

}  // namespace rigcal::gt
