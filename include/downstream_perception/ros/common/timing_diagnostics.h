// A processing time's distribution in diagnostics, the same keys everywhere: "<name> p50 (<unit>)",
// "<name> p99 (<unit>)" (upper bounds: the upper edge of the histogram bin holding them) and
// "<name> histogram (<unit>)" (LogHistogram::encode(): every message of the run, read by the
// replay tool's report). The mean and max keys stay where each nodelet writes them.
#pragma once

#include <diagnostic_updater/DiagnosticStatusWrapper.h>

#include <string>

#include "downstream_perception/core/running_stats.h"

namespace downstream_perception {

inline void addTimingHistogram(diagnostic_updater::DiagnosticStatusWrapper& status,
                               const std::string& name, const std::string& unit,
                               const LogHistogram& histogram) {
  if (histogram.total() == 0) return;
  status.add(name + " p50 (" + unit + ")", histogram.percentile(0.5));
  status.add(name + " p99 (" + unit + ")", histogram.percentile(0.99));
  status.add(name + " histogram (" + unit + ")", histogram.encode());
}

}  // namespace downstream_perception
