#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "downstream_perception/core/handoff/seam_health.h"

using namespace downstream_perception;  // NOLINT

namespace {
double deg(double d) {
  return d * M_PI / 180.0;
}
}  // namespace

TEST(SeamHealth, LessonSmearOf24CentimetresAt5Metres) {
  // 90 deg/s for 30 ms = 2.7 deg; 5 m * tan(0.04712) = 0.2358 m.
  EXPECT_NEAR(expectedSmear(5.0, deg(90), 0.030), 0.2358, 5e-5);
  // The throw scales with range: 4.7 cm at 1 m, 47 cm at 10 m.
  EXPECT_NEAR(expectedSmear(1.0, deg(90), 0.030), 0.0472, 5e-5);
  EXPECT_NEAR(expectedSmear(10.0, deg(90), 0.030), 0.4716, 5e-4);
  // Turning either way, and no turn or no age: no smear.
  EXPECT_DOUBLE_EQ(expectedSmear(5.0, -deg(90), 0.030), expectedSmear(5.0, deg(90), 0.030));
  EXPECT_DOUBLE_EQ(expectedSmear(5.0, 0.0, 0.030), 0.0);
  EXPECT_DOUBLE_EQ(expectedSmear(5.0, deg(90), -1.0), 0.0);
  // A quarter turn or more: the whole range.
  EXPECT_DOUBLE_EQ(expectedSmear(5.0, deg(90), 1.0), 5.0);
}

TEST(SeamHealth, SampleWindowPercentilesOverTheLastSamples) {
  SampleWindow w(100);
  EXPECT_DOUBLE_EQ(w.percentile(0.5), 0.0);
  for (int i = 1; i <= 200; ++i) w.add(i);          // keeps 101..200
  w.add(std::numeric_limits<double>::quiet_NaN());  // ignored
  EXPECT_EQ(w.size(), 100u);
  EXPECT_EQ(w.total(), 200u);
  EXPECT_DOUBLE_EQ(w.percentile(0.5), 150.0);
  EXPECT_DOUBLE_EQ(w.percentile(0.95), 195.0);
  EXPECT_DOUBLE_EQ(w.percentile(1.0), 200.0);
  EXPECT_DOUBLE_EQ(w.percentile(0.0), 101.0);
}

TEST(SeamHealth, SawtoothCorrectionIsHealthy) {
  CorrectionMonitorConfig c;
  c.window_s = 60.0;
  CorrectionMonitor m(c);
  // 2 % drift at 1 m/s, corrected back to 0 every 10 s: 0 -> 0.2 m, snap, repeat.
  for (int k = 0; k <= 600; ++k) {
    const double t = 0.1 * k;
    m.add(t, 0.02 * std::fmod(t, 10.0), t);
  }
  EXPECT_EQ(m.resets(), 6u);  // at 10, 20, ..., 60 s
  EXPECT_FALSE(m.neverResets());
  EXPECT_FALSE(m.stuckAtZero());
  EXPECT_FALSE(m.tooLarge());
  EXPECT_TRUE(m.findings().empty());
}

TEST(SeamHealth, CorrectionThatNeverResetsIsFlagged) {
  CorrectionMonitorConfig c;
  c.window_s = 60.0;
  CorrectionMonitor m(c);
  for (int k = 0; k <= 600; ++k) m.add(0.1 * k, 0.02 * 0.1 * k, 0.1 * k);  // ramps to 1.2 m
  EXPECT_EQ(m.resets(), 0u);
  EXPECT_TRUE(m.neverResets());
  ASSERT_EQ(m.findings().size(), 1u);
  EXPECT_NE(m.findings()[0].find("without ever resetting"), std::string::npos);
  // Past max_correction_m it is also too large.
  m.add(61.0, 2.5, 61.0);
  EXPECT_TRUE(m.tooLarge());
  EXPECT_EQ(m.findings().size(), 2u);
}

TEST(SeamHealth, CorrectionStuckAtZeroWhileTravellingIsFlagged) {
  CorrectionMonitorConfig c;
  c.window_s = 60.0;
  c.min_travel_m = 20.0;
  CorrectionMonitor parked(c), driving(c);
  for (int k = 0; k <= 600; ++k) {
    parked.add(0.1 * k, 0.0, 0.0);             // not moving: zero is fine
    driving.add(0.1 * k, 0.0, 0.5 * 0.1 * k);  // 30 m travelled
  }
  EXPECT_FALSE(parked.stuckAtZero());
  EXPECT_TRUE(driving.stuckAtZero());
  EXPECT_NE(driving.findings().at(0).find("stays zero"), std::string::npos);
}

TEST(SeamHealth, BadSamplesAndConfigs) {
  CorrectionMonitor m;
  m.add(std::numeric_limits<double>::quiet_NaN(), 1.0, 0.0);
  m.add(0.0, std::numeric_limits<double>::infinity(), 0.0);
  EXPECT_DOUBLE_EQ(m.latest(), 0.0);
  CorrectionMonitorConfig c;
  EXPECT_TRUE(c.validate().empty());
  c.window_s = -1.0;
  EXPECT_NE(c.validate().find("window_s"), std::string::npos);
  c = CorrectionMonitorConfig();
  c.reset_drop_m = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(c.validate().find("reset_drop_m"), std::string::npos);
}

TEST(SeamHealth, SeamLimitsAcceptEachValidFieldAndKeepTheRest) {
  SeamLimits current;
  current.max_smear_m = 0.2;  // a value set earlier: what a refused key keeps
  SeamLimits proposed;
  proposed.reference_range_m = std::numeric_limits<double>::quiet_NaN();
  proposed.max_transform_age_s = 0.3;
  proposed.max_smear_m = -0.5;
  proposed.max_map_odom_age_s = 4.0;
  std::vector<std::string> refused;
  const SeamLimits out = SeamLimits::acceptValid(proposed, current, &refused);
  EXPECT_EQ(out.reference_range_m, 5.0);    // the default, kept
  EXPECT_EQ(out.max_transform_age_s, 0.3);  // taken
  EXPECT_EQ(out.max_smear_m, 0.2);          // the earlier value, kept
  EXPECT_EQ(out.max_map_odom_age_s, 4.0);   // taken
  ASSERT_EQ(refused.size(), 2u);
  EXPECT_NE(refused[0].find("reference_range_m"), std::string::npos);
  EXPECT_NE(refused[1].find("max_smear_m = -0.5 must be > 0; keeping 0.2"), std::string::npos);
}
