#include "downstream_perception/ros/common/save_service.h"

#include <ros/console.h>

#include <cstdlib>
#include <sstream>

#include "downstream_perception/ros/common/param_reader.h"

namespace downstream_perception {

std::string defaultOutputDirectory() {
  const char* ros_home = std::getenv("ROS_HOME");
  if (ros_home != nullptr && ros_home[0] == '/') {
    return std::string(ros_home) + "/downstream_perception";
  }
  const char* home = std::getenv("HOME");
  return std::string(home != nullptr && home[0] == '/' ? home : "/tmp") +
         "/.ros/downstream_perception";
}

OutputDirectory readOutputDirectory(const ros::NodeHandle& pnh, ConfigErrorLog* errors) {
  std::string directory = defaultOutputDirectory();
  readParam(pnh, "output_dir", &directory, errors);
  if (directory.empty() || directory.front() != '/') {
    errors->add("parameter ~output_dir = '" + shortenForMessage(directory) +
                "' must be an absolute directory; using " + defaultOutputDirectory());
    directory = defaultOutputDirectory();
  }
  return OutputDirectory(directory);
}

bool serveSave(const char* node, const char* service, const OutputDirectory& directory,
               const std::string& extension, const SaveMap::Request& request,
               SaveMap::Response& response,
               const std::function<bool(std::ostream& out, std::string* what)>& serialise) {
  std::string why = directory.checkName(request.path, extension);
  std::string what;
  OutputFileResult result;
  if (why.empty()) {
    std::ostringstream bytes(std::ios::binary);
    if (!serialise(bytes, &what)) {
      why = what.empty() ? "serialising failed" : what;
    } else {
      result = directory.write(request.path, extension, bytes.str(), request.overwrite);
      why = result.error;
    }
  }
  response.success = why.empty();
  response.written_path = response.success ? result.path : std::string();
  response.message = response.success ? "wrote " + what + " to " + result.path : why;
  if (response.success) {
    ROS_INFO("%s: %s", node, response.message.c_str());
  } else {
    ROS_ERROR("%s: %s refused: %s", node, service, response.message.c_str());
  }
  return true;
}

}  // namespace downstream_perception
