// The one way a service of this package writes a file: a SaveMap request names a file inside
// the node's ~output_dir (OutputDirectory: no escape, no symlink, no silent overwrite, no half
// file) and the reply says what was written where, or why not.
#pragma once

#include <ros/node_handle.h>

#include <functional>
#include <ostream>
#include <string>

#include "downstream_perception/SaveMap.h"
#include "downstream_perception/core/io/output_directory.h"
#include "downstream_perception/ros/common/config_errors.h"

namespace downstream_perception {

/// $ROS_HOME/downstream_perception, or ~/.ros/downstream_perception without ROS_HOME.
std::string defaultOutputDirectory();

/// ~output_dir (absolute; a relative or empty value is a config error and the default is used).
OutputDirectory readOutputDirectory(const ros::NodeHandle& pnh, ConfigErrorLog* errors);

/// Serves one SaveMap request: checks the name first (before any costly work), then
/// `serialise(out)` writes the bytes and returns a description of them ("12 vertices") or
/// false with *why; the result goes to the reply and one log line. Always returns true (the
/// reply carries the failure).
bool serveSave(const char* node, const char* service, const OutputDirectory& directory,
               const std::string& extension, const SaveMap::Request& request,
               SaveMap::Response& response,
               const std::function<bool(std::ostream& out, std::string* what)>& serialise);

}  // namespace downstream_perception
