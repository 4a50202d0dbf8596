// The fingertip proxies are added to a scene through an XML parser: what counts is the document's
// structure, checked here with MuJoCo's own compiled model (the independent reader), not text.
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include "spidar/physics/mjcf_proxies.hpp"
#include "spidar/physics/world.hpp"
#include "temp_path.hpp"

namespace spidar::physics {
namespace {

std::string write(const std::string& dir, const std::string& name, const std::string& text) {
  const std::string path = dir + "/" + name;
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

std::string load_error(const std::string& path) {
  auto w = World::Load(path);
  EXPECT_FALSE(w.ok()) << path << " loaded";
  return w.ok() ? std::string() : w.error().message;
}

// Every place a "</worldbody>" can hide as text: a comment (before, inside and after the real
// element), a CDATA section, a processing instruction and a DOCTYPE before the root, and an
// attribute value (escaped, as XML requires for '<'). A body written inside a comment must not
// become a body either.
TEST(MjcfProxies, WorldbodyTextInCommentsCdataPisAndAttributesIsJustText) {
  const auto dir = spidar::test::temp_dir("mjcf_hiding");
  const std::string path = write(dir, "hiding.xml",
      "<?xml version=\"1.0\"?>\n"
      "<?spidar-note </worldbody> ?>\n"
      "<!DOCTYPE mujoco>\n"
      "<mujoco model=\"a &lt;/worldbody&gt; b\">\n"
      "  <!-- </worldbody> before the real one -->\n"
      "  <worldbody>\n"
      "    <geom type=\"plane\" size=\"1 1 0.1\"/>\n"
      "    <!-- the old floor ended here: </worldbody> <body name=\"ghost\"/> -->\n"
      "    <![CDATA[ </worldbody> ]]>\n"
      "    <body name=\"box\" pos=\"0 0 0.1\"><freejoint/>\n"
      "      <geom type=\"box\" size=\"0.02 0.02 0.02\"/></body>\n"
      "  </worldbody >\n"
      "  <!-- </worldbody> after the real one -->\n"
      "</mujoco>\n");
  auto w = World::Load(path);
  ASSERT_TRUE(w.ok()) << w.error().message;
  const mjModel* m = (*w)->model();
  EXPECT_EQ((*w)->proxies().size(), 8u);
  EXPECT_GE((*w)->body_id("box"), 0);
  EXPECT_EQ((*w)->body_id("ghost"), -1) << "a body inside a comment was created";
  EXPECT_EQ(m->nbody, 1 + 1 + 8);  // world, box, proxies
  for (int i = 0; i < 8; ++i) {
    const int b = (*w)->body_id("proxy_" + std::to_string(i));
    ASSERT_GE(b, 0) << i;
    EXPECT_EQ(m->body_parentid[b], 0) << "proxy_" << i << " is not a child of the world body";
  }
}

TEST(MjcfProxies, ProxiesAreChildrenOfTheWorldbodyWithTheirParameters) {
  ProxyParams p;
  p.count = 3;
  p.radius = 0.0125;
  p.mass = 0.02;
  const auto text = inject_proxies("<mujoco><worldbody><body name=\"a\"/></worldbody></mujoco>", p);
  ASSERT_TRUE(text.ok()) << text.error().message;
  char err[512] = "";
  mjVFS vfs;
  mj_defaultVFS(&vfs);
  ASSERT_EQ(mj_makeEmptyFileVFS(&vfs, "s.xml", static_cast<int>(text->size())), 0);
  std::memcpy(vfs.filedata[mj_findFileVFS(&vfs, "s.xml")], text->data(), text->size());
  mjModel* m = mj_loadXML("s.xml", &vfs, err, sizeof err);
  mj_deleteVFS(&vfs);
  ASSERT_NE(m, nullptr) << err << "\n" << *text;
  EXPECT_EQ(m->nbody, 1 + 1 + 3);
  EXPECT_EQ(m->njnt, 3 * 3);
  for (int i = 0; i < 3; ++i) {
    const int g = mj_name2id(m, mjOBJ_GEOM, ("proxy_" + std::to_string(i) + "_geom").c_str());
    ASSERT_GE(g, 0);
    EXPECT_EQ(m->geom_type[g], mjGEOM_SPHERE);
    EXPECT_DOUBLE_EQ(m->geom_size[3 * g], 0.0125);
    EXPECT_NEAR(m->body_mass[m->geom_bodyid[g]], 0.02, 1e-12);
    EXPECT_EQ(m->body_parentid[m->geom_bodyid[g]], 0);
  }
  mj_deleteModel(m);
}

// Malformed XML gets tinyxml2's error, at its line, with the file's name.
TEST(MjcfProxies, MalformedXmlNamesFileLineAndTinyxml2sError) {
  const auto dir = spidar::test::temp_dir("mjcf_malformed");
  const auto unterminated = write(dir, "comment.xml", "<mujoco>\n<worldbody>\n<!-- never closed </worldbody>\n</mujoco>\n");
  EXPECT_NE(load_error(unterminated).find(unterminated + ":3: malformed XML: XML_ERROR_PARSING_COMMENT"),
            std::string::npos)
      << load_error(unterminated);
  const auto mismatched = write(dir, "mismatch.xml", "<mujoco>\n<worldbody>\n\n<body>\n</worldbody>\n</mujoco>\n");
  const std::string e = load_error(mismatched);
  EXPECT_NE(e.find(mismatched + ":4: malformed XML: XML_ERROR_MISMATCHED_ELEMENT (XMLElement name=body)"),
            std::string::npos) << e;
  const auto empty = write(dir, "empty.xml", "");
  EXPECT_NE(load_error(empty).find(empty + ": not an XML file"), std::string::npos) << load_error(empty);
}

// A file that is not XML at all is named, and not one byte of it is quoted.
TEST(MjcfProxies, NonXmlFileIsNotQuoted) {
  const auto dir = spidar::test::temp_dir("mjcf_not_xml");
  const auto secret = write(dir, "shadow", "root:$6$saltsalt$SECRETHASH:19000:0:99999:7:::\n");
  const std::string e = load_error(secret);
  EXPECT_NE(e.find(secret + ": not an XML file"), std::string::npos) << e;
  EXPECT_EQ(e.find("SECRETHASH"), std::string::npos) << e;
  EXPECT_EQ(e.find("root:"), std::string::npos) << e;
}

TEST(MjcfProxies, WorldbodyMissingDuplicatedOrWrongRootIsAnError) {
  const auto dir = spidar::test::temp_dir("mjcf_structure");
  const auto none = write(dir, "none.xml", "<mujoco>\n  <!-- <worldbody></worldbody> -->\n</mujoco>\n");
  EXPECT_NE(load_error(none).find(none + ": no <worldbody> in <mujoco>"), std::string::npos) << load_error(none);
  const auto two = write(dir, "two.xml", "<mujoco>\n<worldbody/>\n<option/>\n<worldbody>\n</worldbody>\n</mujoco>\n");
  EXPECT_NE(load_error(two).find(two + ":4: a second <worldbody> (the first is at line 2); expected exactly one"),
            std::string::npos)
      << load_error(two);
  const auto root = write(dir, "root.xml", "<robot>\n<worldbody/>\n</robot>\n");
  EXPECT_NE(load_error(root).find(root + ":1: the root element is <robot>; expected <mujoco>"), std::string::npos)
      << load_error(root);
}

// MuJoCo's own errors are quoted against the user's file: its line numbers, not the re-printed
// text's (the parser drops the line breaks inside this multi-line tag).
TEST(MjcfProxies, MujocoErrorsKeepTheScenesLineNumbers) {
  const auto dir = spidar::test::temp_dir("mjcf_lines");
  const auto path = write(dir, "lines.xml",
                          "<mujoco>\n  <worldbody>\n    <geom\n      type=\"plane\"\n"
                          "      size=\"1 1 0.1\"/>\n\n\n    <geom type=\"box\" size=\"0.1 0.1\"/>\n"
                          "  </worldbody>\n</mujoco>\n");
  const std::string e = load_error(path);
  EXPECT_NE(e.find(path + ": MuJoCo could not load the scene: "), std::string::npos) << e;
  EXPECT_NE(e.find("line = 8"), std::string::npos) << e;

  // A scene fine on its own that clashes with the proxies' names says so.
  const auto clash = write(dir, "clash.xml", "<mujoco><worldbody><body name=\"proxy_3\"/></worldbody></mujoco>");
  EXPECT_NE(load_error(clash).find("with the fingertip proxies added"), std::string::npos) << load_error(clash);
}

TEST(MjcfProxies, SceneFileMustBeASmallRegularFileWithASaneTimestep) {
  const auto dir = spidar::test::temp_dir("mjcf_file_kinds");
  EXPECT_NE(load_error(dir).find(dir + ": is a directory"), std::string::npos) << load_error(dir);
  EXPECT_NE(load_error("/dev/zero").find("/dev/zero: is not a regular file"), std::string::npos)
      << load_error("/dev/zero");
  for (const char* dt : {"1", "0.5", "0.003", "1e-06"}) {
    const auto path = write(dir, std::string("dt_") + dt + ".xml",
                            std::string("<mujoco><option timestep=\"") + dt +
                                "\"/><worldbody/></mujoco>");
    const std::string e = load_error(path);
    EXPECT_NE(e.find(path + ": <option timestep=\"" + dt + "\"> is out of range; expected 1e-05 s <= timestep <= 0.002 s"),
              std::string::npos)
        << e;
  }
}

// MuJoCo 2.2.2 compiles "nan" in an attribute silently: the loaded world would step NaN.
TEST(MjcfProxies, NonFiniteNumbersInTheSceneAreRefused) {
  const auto dir = spidar::test::temp_dir("mjcf_nan");
  const auto nan_size = write(dir, "nan_size.xml",
                              "<mujoco><worldbody><geom type=\"sphere\" size=\"0.1\"/>\n"
                              "<geom type=\"sphere\" size=\"nan\" pos=\"0 0 1\"/></worldbody></mujoco>");
  EXPECT_NE(load_error(nan_size).find(nan_size + ": the compiled scene has a non-finite number in geom_size[3]"),
            std::string::npos)
      << load_error(nan_size);
  const auto inf_gravity = write(dir, "inf_gravity.xml",
                                 "<mujoco><option gravity=\"0 0 -inf\"/><worldbody/></mujoco>");
  EXPECT_NE(load_error(inf_gravity).find("non-finite number in option gravity[2]"), std::string::npos)
      << load_error(inf_gravity);
}

// Finite but far beyond any scene on a table: a gravity of 1e308 stepped the cube's state to nan,
// and a cube of 1e30 kg turned its top layer 2348°.
TEST(MjcfProxies, NumbersNoSceneCanMeanAreRefused) {
  const auto dir = spidar::test::temp_dir("mjcf_huge");
  const auto gravity = write(dir, "gravity.xml", "<mujoco><option gravity=\"0 0 -1e308\"/><worldbody/></mujoco>");
  EXPECT_NE(load_error(gravity).find(gravity + ": the compiled scene's option gravity z is -1e+308; expected at most 1000 m/s"),
            std::string::npos)
      << load_error(gravity);
  const auto mass = write(dir, "mass.xml",
                          "<mujoco><worldbody><body name=\"cube\"><freejoint/>"
                          "<geom type=\"box\" size=\"0.03 0.03 0.03\" mass=\"1e30\"/></body></worldbody></mujoco>");
  EXPECT_NE(load_error(mass).find("the compiled scene's body 'cube' mass is 1e+30; expected at most 1e+06 kg"),
            std::string::npos)
      << load_error(mass);
  const auto far = write(dir, "far.xml",
                         "<mujoco><worldbody><body name=\"b\" pos=\"0 5e3 0\"><geom type=\"sphere\" size=\"0.1\"/>"
                         "</body></worldbody></mujoco>");
  EXPECT_NE(load_error(far).find("body 'b' pos y is 5000; expected at most 1000 m"), std::string::npos) << load_error(far);
  const auto unnamed = write(dir, "unnamed.xml",
                             "<mujoco><worldbody><body pos=\"0 0 -2e3\"><geom type=\"sphere\" size=\"0.1\"/>"
                             "</body></worldbody></mujoco>");
  EXPECT_NE(load_error(unnamed).find("body 1 (unnamed) pos z is -2000"), std::string::npos) << load_error(unnamed);
  // The shipped scenes are within every bound.
  for (const char* scene : {"scenes/rubiks_cube.xml", "scenes/blocks.xml"}) {
    const auto w = World::Load(std::string(SPIDAR_SOURCE_DIR) + "/" + scene);
    EXPECT_TRUE(w.ok()) << scene << ": " << (w.ok() ? "" : w.error().message);
  }
}

}  // namespace
}  // namespace spidar::physics
