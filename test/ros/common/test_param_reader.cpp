// ParamReader's conversions and unknown-key detection, without a ROS master: a value of the
// wrong type is refused with a reason that names what was found (never a silent default).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "downstream_perception/ros/common/param_reader.h"

using namespace downstream_perception;  // NOLINT

TEST(ConvertParam, AnIntIsADoubleAsRoscppReadsIt) {
  double v = -1.0;
  EXPECT_EQ(convertParam(XmlRpc::XmlRpcValue(3), &v), "");
  EXPECT_EQ(v, 3.0);
  EXPECT_EQ(convertParam(XmlRpc::XmlRpcValue(0.25), &v), "");
  EXPECT_EQ(v, 0.25);
}

TEST(ConvertParam, TheYamlOneOneExponentTrapIsNamed) {
  // PyYAML (YAML 1.1) loads `1.0e15` as the string "1.0e15".
  double v = 2.5;
  const std::string why = convertParam(XmlRpc::XmlRpcValue(std::string("1.0e15")), &v);
  EXPECT_NE(why.find("'1.0e15' (string)"), std::string::npos) << why;
  EXPECT_NE(why.find("1.0e+15"), std::string::npos) << why;
  EXPECT_EQ(v, 2.5);  // untouched: the caller keeps its default
}

TEST(ConvertParam, WrongTypesAreRefusedWithTheValueFound) {
  bool b = true;
  EXPECT_NE(convertParam(XmlRpc::XmlRpcValue(1), &b).find("1 (int)"), std::string::npos);
  EXPECT_TRUE(b);
  int i = 7;
  EXPECT_NE(convertParam(XmlRpc::XmlRpcValue(2.5), &i).find("not an integer"), std::string::npos);
  EXPECT_EQ(i, 7);
  std::string s = "keep";
  EXPECT_NE(convertParam(XmlRpc::XmlRpcValue(true), &s).find("not a string"), std::string::npos);
  EXPECT_EQ(s, "keep");
  // A plain word in a string is not given the number hint.
  double d = 0.0;
  EXPECT_EQ(convertParam(XmlRpc::XmlRpcValue(std::string("fast")), &d).find("YAML"),
            std::string::npos);
}

TEST(UnknownKeys, NamesEveryMemberNotDeclaredSorted) {
  XmlRpc::XmlRpcValue ns;
  ns["obstacle_range"] = 2.5;
  ns["raytrace_rnage"] = 3.0;  // a typo
  ns["alpha"] = true;
  ns["scan"]["topic"] = std::string("scan");
  const auto unknown = unknownKeys(ns, {"obstacle_range", "scan"});
  ASSERT_EQ(unknown.size(), 2u);
  EXPECT_EQ(unknown[0], "alpha");
  EXPECT_EQ(unknown[1], "raytrace_rnage");
  EXPECT_TRUE(unknownKeys(XmlRpc::XmlRpcValue(1), {}).empty());
}

TEST(ConvertParam, AListOfStringsIsReadWholeOrNotAtAll) {
  XmlRpc::XmlRpcValue list;
  list[0] = std::string("/a/scan");
  list[1] = std::string("/b/scan");
  std::vector<std::string> topics = {"default"};
  EXPECT_EQ(convertParam(list, &topics), "");
  EXPECT_EQ(topics, (std::vector<std::string>{"/a/scan", "/b/scan"}));
  list[2] = 3;
  std::vector<std::string> kept = {"default"};
  EXPECT_EQ(convertParam(list, &kept), "has item 2 3 (int), not a string");
  EXPECT_EQ(kept, std::vector<std::string>{"default"});
  EXPECT_NE(convertParam(XmlRpc::XmlRpcValue(std::string("/a/scan")), &kept)
                .find("not a list of strings"),
            std::string::npos);
}

TEST(ConvertParam, DefaultsAreNamedAsTheyWouldBeWritten) {
  EXPECT_EQ(defaultText(10.0), "10");
  EXPECT_EQ(defaultText(true), "true");
  EXPECT_EQ(defaultText(std::string("odom")), "'odom'");
  EXPECT_EQ(defaultText(std::vector<std::string>{"/a", "/b"}), "['/a', '/b']");
}
