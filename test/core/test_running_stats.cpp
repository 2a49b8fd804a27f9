// The diagnostics statistics: LogHistogram's bins, percentiles and encoding, with edges worked
// out by hand (four bins per decade from 1e-3: edges 1e-3 * 10^(k/4)).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "downstream_perception/core/running_stats.h"

namespace downstream_perception {
namespace {

TEST(LogHistogram, EdgesAreFourPerDecadeFromOneMicro) {
  EXPECT_EQ(LogHistogram::lowerEdge(0), 0.0);
  EXPECT_DOUBLE_EQ(LogHistogram::upperEdge(0), 1e-3);
  EXPECT_DOUBLE_EQ(LogHistogram::lowerEdge(13), 1.0);  // 1e-3 * 10^(12/4)
  EXPECT_NEAR(LogHistogram::upperEdge(13), 1.7782794, 1e-6);
  EXPECT_TRUE(std::isinf(LogHistogram::upperEdge(LogHistogram::kBins - 1)));
}

TEST(LogHistogram, EachSampleLandsInTheBinHoldingIt) {
  LogHistogram h;
  h.add(1.5);                                       // [1, 1.78)
  h.add(0.0);                                       // underflow [0, 0.001)
  h.add(-2.0);                                      // underflow too: not a time
  h.add(1e9);                                       // overflow [1e5, inf)
  h.add(std::numeric_limits<double>::quiet_NaN());  // skipped
  EXPECT_EQ(h.total(), 4u);
  EXPECT_EQ(h.count(13), 1u);
  EXPECT_EQ(h.count(0), 2u);
  EXPECT_EQ(h.count(LogHistogram::kBins - 1), 1u);
  EXPECT_EQ(h.encode(), "0-0.001:2 1-1.78:1 1e+05-inf:1");
}

TEST(LogHistogram, PercentilesAreTheUpperEdgeOfTheirBin) {
  LogHistogram h;
  EXPECT_EQ(h.percentile(0.5), 0.0);        // empty
  for (int k = 0; k < 99; ++k) h.add(0.5);  // [0.316, 0.562)
  h.add(50.0);                              // [31.6, 56.2)
  EXPECT_NEAR(h.percentile(0.5), 0.5623413, 1e-6);
  EXPECT_NEAR(h.percentile(0.99), 0.5623413, 1e-6);  // rank 99 is still a 0.5
  EXPECT_NEAR(h.percentile(1.0), 56.234133, 1e-5);
}

}  // namespace
}  // namespace downstream_perception
