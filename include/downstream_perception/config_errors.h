// Parameter problems in diagnostics: the count and every message, so a user sees all of them in
// rqt_runtime_monitor, not only the first (which is the status summary).
#pragma once

#include <diagnostic_updater/DiagnosticStatusWrapper.h>

#include <sstream>
#include <string>
#include <vector>

namespace downstream_perception {

/// A value as it would print (for "parameter ~x = <value> is invalid" messages).
template <class T>
std::string toText(const T& value) {
  std::ostringstream s;
  s << value;
  return s.str();
}

inline void addConfigErrors(diagnostic_updater::DiagnosticStatusWrapper& status,
                            const std::vector<std::string>& errors) {
  status.add("config errors", errors.size());
  for (std::size_t k = 0; k < errors.size(); ++k) {
    status.add("config error " + std::to_string(k + 1), errors[k]);
  }
}

}  // namespace downstream_perception
