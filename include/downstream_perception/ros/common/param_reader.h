// Parameter reads that never ignore a key silently (the compatibility rule: a costmap_2d YAML key
// keeps its meaning, and a key we do not use is named).
//
// roscpp's param() falls back to the default without a word when the value has another type:
// YAML 1.1 reads `1.0e15` (no sign in the exponent) as a string, `5` for a bool is an int, a
// quoted number is a string. ParamReader reads through one parameter namespace, WARNs once for
// each such value (naming the key, what was found and what is used), records every key it read,
// and at the end WARNs for the keys under the namespace that nobody read. Keys that are read
// elsewhere (dynamic_reconfigure servers, sub-namespaces of sources) are declared with known().
#pragma once

#include <ros/node_handle.h>
#include <xmlrpcpp/XmlRpcValue.h>

#include <set>
#include <string>
#include <vector>

#include "downstream_perception/ros/common/config_errors.h"

namespace downstream_perception {

/// How a raw parameter value converts to T. ROS-free of the master: unit-tested on XmlRpcValues.
/// Returns "" if `raw` holds a T (an int is a double, as roscpp reads it), else why not.
std::string convertParam(const XmlRpc::XmlRpcValue& raw, double* value);
std::string convertParam(const XmlRpc::XmlRpcValue& raw, int* value);
std::string convertParam(const XmlRpc::XmlRpcValue& raw, bool* value);
std::string convertParam(const XmlRpc::XmlRpcValue& raw, std::string* value);
std::string convertParam(const XmlRpc::XmlRpcValue& raw, std::vector<std::string>* value);

/// A default as readParam's error names it (lists joined, strings quoted).
inline std::string defaultText(const std::string& v) {
  return "'" + v + "'";
}
inline std::string defaultText(const std::vector<std::string>& v) {
  std::string text = "[";
  for (std::size_t k = 0; k < v.size(); ++k) text += (k ? ", '" : "'") + v[k] + "'";
  return text + "]";
}
inline std::string defaultText(bool v) {
  return v ? "true" : "false";
}
template <class T>
std::string defaultText(const T& v) {
  return toText(v);
}

/// nh.param(key, *value, *value) without its silent fallback: a value of the wrong type leaves
/// *value (the default) and returns why ("" when the key is unset or was read). For nodelets that
/// read their own keys one by one (TSDF, tracker, handoff); layers use ParamReader.
template <class T>
std::string readParam(const ros::NodeHandle& nh, const std::string& key, T* value) {
  XmlRpc::XmlRpcValue raw;
  if (!nh.getParam(key, raw)) return "";
  T read{};
  const std::string why = convertParam(raw, &read);
  if (why.empty()) *value = read;
  return why;
}

/// readParam() whose wrong type is a config error: "parameter ~key is ..., not ...; using the
/// default <value>" (logged, and counted in the component's diagnostics).
template <class T>
void readParam(const ros::NodeHandle& nh, const std::string& key, T* value,
               ConfigErrorLog* errors) {
  const std::string why = readParam(nh, key, value);
  if (why.empty()) return;
  errors->add("parameter ~" + key + " " + why + "; using the default " + defaultText(*value));
}

/// The member names of `ns_value` (a struct) that are not in `known`, sorted.
std::vector<std::string> unknownKeys(const XmlRpc::XmlRpcValue& ns_value,
                                     const std::set<std::string>& known);

class ParamReader {
 public:
  /// `who` prefixes every log line, e.g. "layer 'obstacles'".
  ParamReader(ros::NodeHandle nh, std::string who);

  /// Reads `key` into *value when it is set and has the right type; otherwise keeps *value (the
  /// default) and, for a value of the wrong type, WARNs. Returns whether the key was set and used.
  template <class T>
  bool get(const std::string& key, T* value);
  /// get() with an explicit default.
  template <class T>
  T param(const std::string& key, const T& fallback) {
    T value = fallback;
    get(key, &value);
    return value;
  }
  bool has(const std::string& key) const { return nh_.hasParam(key); }
  /// Declares keys that are read elsewhere (a dynamic_reconfigure server, a sub-namespace).
  void known(const std::vector<std::string>& keys);
  /// Declares the keys of a dynamic_reconfigure Config type and checks the type of those that
  /// are set: the server itself would fall back to its default without a word.
  template <class ReconfigureConfig>
  void reconfigureKeys() {
    for (const auto& description : ReconfigureConfig::__getParamDescriptions__()) {
      checkType(description->name, description->type);
    }
  }
  /// Declares a key that costmap_2d reads but we do not implement: WARNs (once) if it is set.
  void unsupported(const std::string& key, const std::string& why);
  /// WARNs once for each key under the namespace that was neither read nor declared known;
  /// returns them (for diagnostics).
  std::vector<std::string> warnUnknown();

  /// Every WARN this reader issued (wrong types, unsupported, unknown), for diagnostics.
  const std::vector<std::string>& warnings() const { return warnings_; }
  const ros::NodeHandle& nodeHandle() const { return nh_; }

 private:
  void warn(const std::string& msg);
  /// `type` as dynamic_reconfigure names it: "double", "int", "bool", "str".
  void checkType(const std::string& key, const std::string& type);

  ros::NodeHandle nh_;
  std::string who_;
  std::set<std::string> known_;
  std::vector<std::string> warnings_;
};

}  // namespace downstream_perception
