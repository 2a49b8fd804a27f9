// ConfigErrorLog: lasting errors stay; a keyed error is replaced by the next one of its key and
// leaves the diagnostics once its key is fixed.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "downstream_perception/ros/common/config_errors.h"

namespace downstream_perception {
namespace {

std::string summaryOf(const ConfigErrorLog& log, bool* any) {
  diagnostic_updater::DiagnosticStatusWrapper status;
  status.summary(diagnostic_msgs::DiagnosticStatus::OK, "fine");
  *any = log.report(status);
  return status.message;
}

TEST(ConfigErrorLog, KeyedErrorDisappearsOnceFixed) {
  ConfigErrorLog log;
  log.set("p_hit", "p_hit 1.5 rejected");
  bool any = false;
  EXPECT_EQ(summaryOf(log, &any), "p_hit 1.5 rejected");
  EXPECT_TRUE(any);
  log.clear("p_hit");
  EXPECT_EQ(summaryOf(log, &any), "fine");
  EXPECT_FALSE(any);
  EXPECT_TRUE(log.all().empty());
}

TEST(ConfigErrorLog, AKeyHoldsOnlyItsLatestError) {
  ConfigErrorLog log;
  log.set("p_hit", "p_hit 1.5 rejected");
  log.set("decay", "decay -1 rejected");
  log.set("p_hit", "p_hit 2.5 rejected");
  EXPECT_EQ(log.all(), (std::vector<std::string>{"p_hit 2.5 rejected", "decay -1 rejected"}));
  log.clear("decay");
  EXPECT_EQ(log.all(), (std::vector<std::string>{"p_hit 2.5 rejected"}));
}

TEST(ConfigErrorLog, LastingErrorsStayAndComeFirst) {
  ConfigErrorLog log;
  log.set("p_hit", "p_hit 1.5 rejected");
  log.add("source 'x': data_type 'Foo' is not supported");
  log.clear("p_hit");
  log.clear("something else");
  EXPECT_EQ(log.all(), (std::vector<std::string>{"source 'x': data_type 'Foo' is not supported"}));
  bool any = false;
  EXPECT_EQ(summaryOf(log, &any), "source 'x': data_type 'Foo' is not supported");
}

// The costmap host's use (formerly its own ConfigErrors): a group of numbered keys read again as
// a whole replaces the old group, problems found into a scratch log are merged in by key.
TEST(ConfigErrorLog, PrefixClearAndMergeKeepTheOrderOfFirstAppearance) {
  ConfigErrorLog log("costmap");
  log.keep("footprint 0", "point 0 is not finite");
  log.keep("update_frequency", "update_frequency -1 is invalid");
  log.keep("footprint 1", "point 1 is not finite");
  EXPECT_FALSE(log.empty());

  ConfigErrorLog scratch("costmap");
  scratch.keep("footprint 0", "fewer than 3 points");
  scratch.keep("update_frequency", "update_frequency 0 is invalid");
  log.clearWithPrefix("footprint ");
  EXPECT_EQ(log.all(), (std::vector<std::string>{"update_frequency -1 is invalid"}));
  log.merge(scratch);
  // update_frequency keeps its place (replaced in place); the new footprint entry comes after.
  EXPECT_EQ(log.all(),
            (std::vector<std::string>{"update_frequency 0 is invalid", "fewer than 3 points"}));
  log.clearWithPrefix("update_frequency");
  log.clearWithPrefix("footprint ");
  EXPECT_TRUE(log.empty());
}

}  // namespace
}  // namespace downstream_perception
