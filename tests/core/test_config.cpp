#include <gtest/gtest.h>

#include <fstream>

#include "config_error_of.hpp"
#include "spidar/core/config.hpp"
#include "spidar/core/pose.hpp"

namespace spidar::core {
namespace {

using testing::error_of;

TEST(ConfigNode, ReadsTypedValues) {
  auto root = ConfigNode::Parse("a: 1.5\nb: [1, 2, 3]\nc: hello\nd: true\ne: 7\n", "t.yaml");
  EXPECT_DOUBLE_EQ(root["a"].as_double(), 1.5);
  EXPECT_EQ(root["b"].as_vec3(), Vec3(1, 2, 3));
  EXPECT_EQ(root["c"].as_string(), "hello");
  EXPECT_TRUE(root["d"].as_bool());
  EXPECT_EQ(root["e"].as_int(), 7);
  EXPECT_EQ(root.get_double("missing", 4.0), 4.0);
  EXPECT_FALSE(root.find("missing").has_value());
  EXPECT_EQ(root.keys(), (std::vector<std::string>{"a", "b", "c", "d", "e"}));
}

TEST(ConfigNode, ErrorNamesFileLineAndKeyPath) {
  const char* text =
      "fingers:\n"
      "  - name: a\n"
      "    fulcrums:\n"
      "      - [1, 2, 3]\n"
      "      - [1, 2]\n";
  auto root = ConfigNode::Parse(text, "configs/x.yaml");
  EXPECT_EQ(error_of([&] { root["fingers"].at(0)["fulcrums"].at(1).as_vec3(); }),
            "configs/x.yaml:5: fingers[0].fulcrums[1]: expected 3 numbers, got 2");
}

TEST(ConfigNode, MissingKeyNamesTheKeyAndParentLine) {
  auto root = ConfigNode::Parse("a:\n  b: 1\n", "f.yaml");
  EXPECT_EQ(error_of([&] { root["a"]["c"]; }), "f.yaml:2: a: missing required key 'c'");
}

TEST(ConfigNode, RejectsWrongTypesAndNonFiniteNumbers) {
  auto root = ConfigNode::Parse("a: abc\nb: .nan\nc: [1, 2]\nd: {x: 1}\n", "f.yaml");
  EXPECT_EQ(error_of([&] { root["a"].as_double(); }), "f.yaml:1: a: expected a number, got 'abc'");
  EXPECT_EQ(error_of([&] { root["b"].as_double(); }),
            "f.yaml:2: b: expected a finite number, got '.nan'");
  EXPECT_EQ(error_of([&] { root["d"].as_vec3(); }), "f.yaml:4: d: expected 3 numbers, got a map");
  EXPECT_EQ(error_of([&] { root["c"].at(5); }), "f.yaml:3: c: index 5 out of range");
  EXPECT_EQ(error_of([&] { root["a"].as_int(); }), "f.yaml:1: a: expected an integer, got 'abc'");
}

TEST(ConfigNode, UnknownKeysAreReportedWithTheAllowedOnes) {
  auto root = ConfigNode::Parse("name: x\nfulcrum: 1\n", "f.yaml");
  EXPECT_EQ(error_of([&] { root.expect_keys({"name", "fulcrums"}); }),
            "f.yaml:2: fulcrum: unknown key; expected one of: name, fulcrums");
}

TEST(ConfigNode, MalformedYamlAndMissingFiles) {
  EXPECT_EQ(error_of([] { ConfigNode::Parse("a: [1, 2\n", "bad.yaml"); }).rfind("bad.yaml:", 0),
            0u);
  EXPECT_NE(error_of([] { ConfigNode::Parse("a: [1, 2\n", "bad.yaml"); }).find("malformed YAML"),
            std::string::npos);
  EXPECT_EQ(error_of([] { ConfigNode::LoadFile("/nonexistent/x.yaml"); }),
            "/nonexistent/x.yaml: cannot open file (does it exist and is it readable?)");
  EXPECT_EQ(error_of([] { ConfigNode::Parse("- 1\n- 2\n", "list.yaml"); }),
            "list.yaml:1: expected a YAML map at the top level");
}

TEST(ConfigNode, RangeCheck) {
  auto root = ConfigNode::Parse("t: 40\n", "f.yaml");
  EXPECT_EQ(error_of([&] { require_in_range(root["t"], root["t"].as_double(), 0, 30, "N"); }),
            "f.yaml:1: t: expected a value in [0, 30] N, got 40");
}

TEST(Pose, ComposesAndInverts) {
  const Pose X_AB = Pose::FromRotationVector(Vec3(0.1, -0.4, 0.3), Vec3(1, 2, 3));
  const Pose X_BC = Pose::FromRotationVector(Vec3(-0.7, 0.2, 0.05), Vec3(-0.5, 0.1, 0.2));
  const Vec3 p_CQ(0.3, -0.2, 0.9);
  EXPECT_TRUE(((X_AB * X_BC) * p_CQ).isApprox(X_AB * (X_BC * p_CQ), 1e-14));
  EXPECT_TRUE((X_AB.inverse() * (X_AB * p_CQ)).isApprox(p_CQ, 1e-14));
  const Mat4 M = X_AB.matrix();
  EXPECT_TRUE((M * p_CQ.homogeneous()).head<3>().isApprox(X_AB * p_CQ, 1e-14));
  EXPECT_TRUE(Pose::FromRotationVector(Vec3::Zero(), Vec3::Zero()).R.isApprox(Quat::Identity()));
}

}  // namespace
}  // namespace spidar::core
