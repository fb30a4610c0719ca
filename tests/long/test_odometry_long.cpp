// The long form of the odometry's covariance honesty (tests/unit/test_odometry.cpp has the
// short one, OS1-64 seeds 6-10): the OS0-128 preset on the simulator's street drive at 10 Hz,
// seeds 1-5, 20 sweeps each (about 0.6 s of ray casting a sweep), and the OS1-64 preset over ten
// more seeds. Figures in doc/odometry.md; seed 19 of the OS1-64 is a street whose geometry barely
// fixes the motion along it (the corridor's case, test_odometry.cpp, Degeneracy.*).
#include "odometry_honesty.h"

namespace rigcal::lidar {
namespace {

TEST(OdometryHonestyLong, Os0_128StepErrorsLieWithinThreeSigmaInAtLeast95PercentOfSteps) {
  const HonestyFigures h = odometry_honesty(sim::os0_128(), os0_128_handheld(), 1, 5, 20);
  EXPECT_GE(double(h.within), 0.95 * double(h.steps));
  EXPECT_GE(double(h.unwidened_within), 0.95 * double(h.steps - h.widened));
  EXPECT_GT(h.nees_mean, 1.0);
}

TEST(OdometryHonestyLong, Os1_64StepErrorsOverTenSeeds) {
  const HonestyFigures h = odometry_honesty(sim::os1_64(), os1_64_car(), 11, 20, 20);
  EXPECT_GE(double(h.within), 0.95 * double(h.steps));
  EXPECT_GE(double(h.unwidened_within), 0.95 * double(h.steps - h.widened));
  EXPECT_GT(h.nees_mean, 1.0);
}

}  // namespace
}  // namespace rigcal::lidar
