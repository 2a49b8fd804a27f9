#include "downstream_perception/ros/common/param_reader.h"

#include <ros/console.h>

#include <cstdlib>
#include <sstream>

namespace downstream_perception {

namespace {

const char* typeName(const XmlRpc::XmlRpcValue& raw) {
  switch (raw.getType()) {
    case XmlRpc::XmlRpcValue::TypeBoolean:
      return "bool";
    case XmlRpc::XmlRpcValue::TypeInt:
      return "int";
    case XmlRpc::XmlRpcValue::TypeDouble:
      return "double";
    case XmlRpc::XmlRpcValue::TypeString:
      return "string";
    case XmlRpc::XmlRpcValue::TypeArray:
      return "list";
    case XmlRpc::XmlRpcValue::TypeStruct:
      return "dictionary";
    default:
      return "other";
  }
}

std::string describe(const XmlRpc::XmlRpcValue& raw) {
  std::ostringstream text;
  if (raw.getType() == XmlRpc::XmlRpcValue::TypeString) {
    text << "'" << static_cast<std::string>(XmlRpc::XmlRpcValue(raw)) << "'";
  } else if (raw.getType() == XmlRpc::XmlRpcValue::TypeArray ||
             raw.getType() == XmlRpc::XmlRpcValue::TypeStruct) {
    text << "a " << typeName(raw);
    return text.str();
  } else {
    XmlRpc::XmlRpcValue copy(raw);
    copy.write(text);
  }
  return text.str() + " (" + typeName(raw) + ")";
}

// A string that is a whole number: the YAML 1.1 trap (`1.0e15`, `"0.5"`) gets its own hint.
bool looksNumeric(const XmlRpc::XmlRpcValue& raw) {
  if (raw.getType() != XmlRpc::XmlRpcValue::TypeString) return false;
  const std::string s = static_cast<std::string>(XmlRpc::XmlRpcValue(raw));
  if (s.empty()) return false;
  char* end = nullptr;
  std::strtod(s.c_str(), &end);
  return end != nullptr && *end == '\0';
}

std::string wrongType(const XmlRpc::XmlRpcValue& raw, const char* wanted) {
  std::string why = "is " + describe(raw) + ", not " + wanted;
  if (looksNumeric(raw)) {
    why +=
        " (YAML 1.1 reads a number such as 1.0e15 without a sign in its exponent, or a quoted "
        "number, as a string: write 1.0e+15)";
  }
  return why;
}

template <class T>
std::string printed(const T& value) {
  std::ostringstream text;
  text << std::boolalpha << value;
  return text.str();
}

}  // namespace

std::string convertParam(const XmlRpc::XmlRpcValue& raw, double* value) {
  XmlRpc::XmlRpcValue v(raw);
  if (v.getType() == XmlRpc::XmlRpcValue::TypeDouble) {
    *value = static_cast<double>(v);
    return "";
  }
  if (v.getType() == XmlRpc::XmlRpcValue::TypeInt) {
    *value = static_cast<int>(v);
    return "";
  }
  return wrongType(raw, "a number");
}

std::string convertParam(const XmlRpc::XmlRpcValue& raw, int* value) {
  XmlRpc::XmlRpcValue v(raw);
  if (v.getType() == XmlRpc::XmlRpcValue::TypeInt) {
    *value = static_cast<int>(v);
    return "";
  }
  return wrongType(raw, "an integer");
}

std::string convertParam(const XmlRpc::XmlRpcValue& raw, bool* value) {
  XmlRpc::XmlRpcValue v(raw);
  if (v.getType() == XmlRpc::XmlRpcValue::TypeBoolean) {
    *value = static_cast<bool>(v);
    return "";
  }
  return wrongType(raw, "true / false");
}

std::string convertParam(const XmlRpc::XmlRpcValue& raw, std::string* value) {
  XmlRpc::XmlRpcValue v(raw);
  if (v.getType() == XmlRpc::XmlRpcValue::TypeString) {
    *value = static_cast<std::string>(v);
    return "";
  }
  return wrongType(raw, "a string");
}

std::string convertParam(const XmlRpc::XmlRpcValue& raw, std::vector<std::string>* value) {
  XmlRpc::XmlRpcValue v(raw);
  if (v.getType() != XmlRpc::XmlRpcValue::TypeArray) return wrongType(raw, "a list of strings");
  std::vector<std::string> out;
  for (int k = 0; k < v.size(); ++k) {
    if (v[k].getType() != XmlRpc::XmlRpcValue::TypeString) {
      return "has item " + std::to_string(k) + " " + describe(v[k]) + ", not a string";
    }
    out.push_back(static_cast<std::string>(v[k]));
  }
  *value = out;
  return "";
}

std::vector<std::string> unknownKeys(const XmlRpc::XmlRpcValue& ns_value,
                                     const std::set<std::string>& known) {
  std::vector<std::string> unknown;
  if (ns_value.getType() != XmlRpc::XmlRpcValue::TypeStruct) return unknown;
  XmlRpc::XmlRpcValue copy(ns_value);
  for (const auto& member : copy) {
    if (known.count(member.first) == 0) unknown.push_back(member.first);
  }
  return unknown;  // std::map order: sorted
}

ParamReader::ParamReader(ros::NodeHandle nh, std::string who)
    : nh_(std::move(nh)), who_(std::move(who)) {}

template <class T>
bool ParamReader::get(const std::string& key, T* value) {
  known_.insert(key);
  XmlRpc::XmlRpcValue raw;
  if (!nh_.getParam(key, raw)) return false;
  T converted = *value;
  const std::string why = convertParam(raw, &converted);
  if (!why.empty()) {
    warn("parameter " + nh_.resolveName(key) + " " + why + "; using " + printed(*value));
    return false;
  }
  *value = converted;
  return true;
}

template bool ParamReader::get<double>(const std::string&, double*);
template bool ParamReader::get<int>(const std::string&, int*);
template bool ParamReader::get<bool>(const std::string&, bool*);
template bool ParamReader::get<std::string>(const std::string&, std::string*);

void ParamReader::known(const std::vector<std::string>& keys) {
  known_.insert(keys.begin(), keys.end());
}

void ParamReader::unsupported(const std::string& key, const std::string& why) {
  known_.insert(key);
  if (nh_.hasParam(key)) warn("parameter " + nh_.resolveName(key) + " is not supported: " + why);
}

std::vector<std::string> ParamReader::warnUnknown() {
  XmlRpc::XmlRpcValue all;
  if (!nh_.getParam(nh_.getNamespace(), all)) return {};
  const std::vector<std::string> unknown = unknownKeys(all, known_);
  for (const auto& key : unknown) {
    warn("parameter " + nh_.resolveName(key) + " is not a key of this component; ignored");
  }
  return unknown;
}

void ParamReader::checkType(const std::string& key, const std::string& type) {
  if (type == "double") {
    double v = 0.0;
    get(key, &v);
  } else if (type == "int") {
    int v = 0;
    get(key, &v);
  } else if (type == "bool") {
    bool v = false;
    get(key, &v);
  } else {
    std::string v;
    get(key, &v);
  }
}

void ParamReader::warn(const std::string& msg) {
  for (const auto& earlier : warnings_) {
    if (earlier == msg) return;  // a key read twice is named once
  }
  ROS_WARN("%s: %s", who_.c_str(), msg.c_str());
  warnings_.push_back(msg);
}

}  // namespace downstream_perception
