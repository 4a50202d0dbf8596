// ConfigNode on hostile input: files that are not regular or too large, deep nesting, duplicate
// keys, content that must not be echoed, and wrong node shapes.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <functional>
#include <future>

#include "config_error_of.hpp"
#include "spidar/core/config.hpp"
#include "temp_dir.hpp"

namespace spidar::core {
namespace {

using testing::TempDir;

using testing::error_of;

const std::string kTooDeep = "expected at most 64 levels of nested maps and sequences";

std::string repeat(std::string_view s, int n) {
  std::string out;
  for (int i = 0; i < n; ++i) out += s;
  return out;
}

/// `n` maps nested by indentation (the top-level map is the first), the last holding `v: 1` on
/// line `n`.
std::string nested_block_maps(int n) {
  std::string out;
  for (int i = 0; i + 1 < n; ++i) {
    out += std::string(2 * i, ' ') + "k" + std::to_string(i) + ":\n";
  }
  return out + std::string(2 * (n - 1), ' ') + "v: 1\n";
}

TEST(ConfigLimits, LoadFileRefusesADirectory) {
  TempDir dir;
  EXPECT_EQ(error_of([&] { ConfigNode::LoadFile(dir.path()); }), dir.path() + ": is a directory");
}

TEST(ConfigLimits, LoadFileRefusesADevice) {
  EXPECT_EQ(error_of([] { ConfigNode::LoadFile("/dev/zero"); }),
            "/dev/zero: is not a regular file");
}

TEST(ConfigLimits, LoadFileRefusesAFifoWithoutBlocking) {
  TempDir dir;
  const std::string fifo = dir.path() + "/lab.yaml";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  auto result =
      std::async(std::launch::async, [&] { return error_of([&] { ConfigNode::LoadFile(fifo); }); });
  // Should LoadFile block in open(), a writer releases it so the test fails instead of hanging.
  if (result.wait_for(std::chrono::seconds(10)) == std::future_status::timeout) {
    ADD_FAILURE() << "LoadFile blocked on a FIFO";
    const int fd = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK);
    if (fd >= 0) ::close(fd);
  }
  EXPECT_EQ(result.get(), fifo + ": is not a regular file");
}

TEST(ConfigLimits, LoadFileRefusesAFileAboveTheCap) {
  TempDir dir;
  const std::string big = "a: 1\n" + std::string(kMaxConfigFileBytes + 1 - 5, '#');
  ASSERT_EQ(big.size(), kMaxConfigFileBytes + 1);
  const auto path = dir.write("big.yaml", big);
  EXPECT_EQ(error_of([&] { ConfigNode::LoadFile(path); }),
            path + ": 1048577 bytes, more than the 1048576 allowed for a config file");
  // Exactly at the cap is read (it is one comment after `a: 1`).
  const auto at_cap = dir.write("at_cap.yaml", big.substr(0, kMaxConfigFileBytes));
  EXPECT_EQ(ConfigNode::LoadFile(at_cap)["a"].as_int(), 1);
  // The cap is a parameter.
  EXPECT_EQ(error_of([&] { ConfigNode::LoadFile(dir.write("small.yaml", "a: 12345\n"), 8); }),
            dir.path() + "/small.yaml: 9 bytes, more than the 8 allowed for a config file");
}

TEST(ConfigLimits, LoadFileRefusesAPathWithANulCharacter) {
  TempDir dir;
  dir.write("lab", "a: 1\n");  // what the path would name if cut at the NUL
  const std::string path = dir.path() + "/lab" + std::string(1, '\0') + ".yaml";
  EXPECT_EQ(error_of([&] { ConfigNode::LoadFile(path); }),
            dir.path() + "/lab\\x00.yaml: path contains a NUL character");
}

TEST(ConfigLimits, LoadFileStillReadsAConfigAndReportsMissingFiles) {
  TempDir dir;
  EXPECT_EQ(ConfigNode::LoadFile(dir.write("ok.yaml", "a: [1, 2, 3]\n"))["a"].as_vec3(),
            Vec3(1, 2, 3));
  EXPECT_EQ(error_of([] { ConfigNode::LoadFile("/nonexistent/x.yaml"); }),
            "/nonexistent/x.yaml: cannot open file (does it exist and is it readable?)");
}

TEST(ConfigLimits, DeepFlowNestingIsRefusedBeforeParsing) {
  EXPECT_EQ(error_of([] { ConfigNode::Parse(std::string(100000, '['), "deep.yaml"); }),
            "deep.yaml:1: " + kTooDeep);
  EXPECT_EQ(error_of([] { ConfigNode::Parse("a:\n  b: " + std::string(100000, '{'), "d.yaml"); }),
            "d.yaml:2: " + kTooDeep);
  EXPECT_EQ(error_of([] { ConfigNode::Parse(repeat("- ", 100000) + "x\n", "dash.yaml"); }),
            "dash.yaml:1: " + kTooDeep);
  TempDir dir;
  const auto path = dir.write("deep.yaml", "a: " + std::string(100000, '['));
  EXPECT_EQ(error_of([&] { ConfigNode::LoadFile(path); }), path + ":1: " + kTooDeep);
  // Refused before yaml-cpp sees it: the parser would report the unclosed sequence instead.
  EXPECT_EQ(error_of([] { ConfigNode::Parse("a: " + std::string(100, '[') + "1", "u.yaml"); }),
            "u.yaml:1: " + kTooDeep);
}

TEST(ConfigLimits, WhenTheTextScanIsFooledTheParserLimitAndTheTreeCheckStillRefuse) {
  // In a flow sequence `a:'b` is a plain scalar, but the text scan takes the quote as opening a
  // string and stops counting brackets. yaml-cpp's own recursion limit (2000) then stops the
  // parse, and is reported as the same nesting error; below that limit, the tree check does.
  EXPECT_EQ(error_of([] { ConfigNode::Parse("x: [a:'b, " + std::string(100000, '['), "f.yaml"); }),
            "f.yaml:1: " + kTooDeep);
  const auto message = error_of([] {
    ConfigNode::Parse("x: [a:'b, " + std::string(100, '[') + std::string(101, ']'), "f.yaml");
  });
  EXPECT_EQ(message.rfind("f.yaml:1: x[1][0][0]", 0), 0u) << message;
  EXPECT_NE(message.find(kTooDeep), std::string::npos) << message;
}

TEST(ConfigLimits, NestingUpToTheLimitIsAccepted) {
  // The top-level map is level 1, so 63 flow sequences inside it make 64 levels.
  const auto flow = [](int n) {
    return "a: " + std::string(n, '[') + "1" + std::string(n, ']') + "\n";
  };
  EXPECT_EQ(error_of([&] { ConfigNode::Parse(flow(63), "f.yaml"); }), "no error");
  EXPECT_EQ(error_of([&] { ConfigNode::Parse(flow(64), "f.yaml"); }), "f.yaml:1: " + kTooDeep);
  EXPECT_EQ(error_of([] { ConfigNode::Parse(nested_block_maps(64), "b.yaml"); }), "no error");
  EXPECT_EQ(error_of([] { ConfigNode::Parse(nested_block_maps(65), "b.yaml"); }),
            "b.yaml:65: " + kTooDeep);
  EXPECT_EQ(error_of([] { ConfigNode::Parse("a:\n" + repeat("- ", 63) + "x\n", "s.yaml"); }),
            "no error");
  EXPECT_EQ(error_of([] { ConfigNode::Parse("a:\n" + repeat("- ", 64) + "x\n", "s.yaml"); }),
            "s.yaml:2: " + kTooDeep);
}

TEST(ConfigLimits, BracketsInStringsCommentsAndBlockScalarsAreNotNesting) {
  const std::string many(200, '[');
  const std::string text = "a: '" + many + "'\n" +              // single-quoted
                           "b: \"\\\"" + many + "\"\n" +        // double-quoted, with an escape
                           "c: it's " + many + "\n" +           // plain scalar
                           "# " + many + "\n" +                 // comment
                           "d: |\n  " + many + "\n  " + many +  // block scalar
                           "\ne: ['" + many + "', \"]]]\"]\n";  // strings inside a flow sequence
  const auto root = ConfigNode::Parse(text, "q.yaml");
  EXPECT_EQ(root["a"].as_string(), many);
  EXPECT_EQ(root["e"].size(), 2u);
}

TEST(ConfigLimits, NestingThroughAliasesIsCheckedOnTheTree) {
  // Each half is 40 deep in the text; the alias puts one inside the other.
  const std::string text = "a: &x " + std::string(40, '[') + "1" + std::string(40, ']') +
                           "\nb: " + std::string(40, '[') + "*x" + std::string(40, ']') + "\n";
  const auto message = error_of([&] { ConfigNode::Parse(text, "alias.yaml"); });
  EXPECT_EQ(message.rfind("alias.yaml:", 0), 0u) << message;
  EXPECT_NE(message.find(kTooDeep), std::string::npos) << message;
  // An alias to its own anchor makes a cycle.
  EXPECT_NE(error_of([] { ConfigNode::Parse("a: &c [*c]\n", "cycle.yaml"); }).find(kTooDeep),
            std::string::npos);
}

TEST(ConfigLimits, ExponentialAliasExpansionIsBounded) {
  std::string text = "l0: &l0 [x, x, x, x, x, x, x, x, x, x]\n";
  for (int i = 1; i < 9; ++i) {
    const auto prev = "*l" + std::to_string(i - 1);
    text += "l" + std::to_string(i) + ": &l" + std::to_string(i) + " [" + prev;
    for (int k = 1; k < 10; ++k) text += ", " + prev;
    text += "]\n";
  }
  const auto message = error_of([&] { ConfigNode::Parse(text, "laughs.yaml"); });
  EXPECT_NE(message.find("expected at most 1000000 values in the document"), std::string::npos)
      << message;
}

TEST(ConfigLimits, DuplicateKeysAreErrorsWithBothLines) {
  EXPECT_EQ(error_of([] { ConfigNode::Parse("device: a\nrate: 1\ndevice: b\n", "dup.yaml"); }),
            "dup.yaml:3: duplicate key 'device' (first at line 1)");
  EXPECT_EQ(error_of([] { ConfigNode::Parse("camera:\n  fx: 1\n  fy: 2\n  fx: 3\n", "dup.yaml"); }),
            "dup.yaml:4: camera: duplicate key 'fx' (first at line 2)");
  EXPECT_EQ(error_of([] { ConfigNode::Parse("m:\n  - a: 0\n  - {k: 1, k: 2}\n", "dup.yaml"); }),
            "dup.yaml:3: m[1]: duplicate key 'k' (first at line 3)");
  EXPECT_EQ(error_of([] { ConfigNode::Parse("'a': 1\n\"a\": 2\n", "dup.yaml"); }),
            "dup.yaml:2: duplicate key 'a' (first at line 1)");
  TempDir dir;
  const auto path = dir.write("lab.yaml", "device:\n  backend: sim\n  backend: serial\n");
  EXPECT_EQ(error_of([&] { ConfigNode::LoadFile(path); }),
            path + ":3: device: duplicate key 'backend' (first at line 2)");
}

TEST(ConfigLimits, ContentOfAFileThatIsNotAConfigIsNotEchoed) {
  TempDir dir;
  // Lines like /etc/shadow's parse as a map whose keys are the whole lines.
  const auto shadow = dir.write("shadow",
                                "root:$6$SECRETsalt$SECREThashSECRET:19000:0:99999:7:::\n"
                                "daemon:*:19000:0:99999:7:::\n");
  const auto message = error_of([&] { ConfigNode::LoadFile(shadow).expect_keys({"device"}); });
  EXPECT_EQ(message, shadow + ":1: <key on line 1>: unknown key; expected one of: device");
  // Binary data.
  const auto binary =
      dir.write("blob", std::string("\177ELF\2\1\1\0\0SECRET\377\376:\n\tSECRET: [\"SECRET\n", 32));
  const auto blob_message = error_of([&] { ConfigNode::LoadFile(binary); });
  EXPECT_EQ(blob_message.rfind(binary + ":", 0), 0u) << blob_message;
  EXPECT_EQ(blob_message.find("SECRET"), std::string::npos) << blob_message;
  // yaml-cpp appends the offending character to some messages; only the fixed part is kept.
  EXPECT_EQ(error_of([] { ConfigNode::Parse("a: \"\\qSECRET\"\n", "esc.yaml"); }),
            "esc.yaml:1: malformed YAML: unknown escape character (column 7)");
  // A value that is not a plain word is described, not quoted.
  const auto root =
      ConfigNode::Parse("k: $6$SECRET/hash\nlong: " + std::string(60, 'x') + "\n", "v.yaml");
  EXPECT_EQ(error_of([&] { root["k"].as_double(); }),
            "v.yaml:1: k: expected a number, got a text of 14 characters (not shown)");
  EXPECT_EQ(error_of([&] { root["long"].as_int(); }),
            "v.yaml:2: long: expected an integer, got a text of 60 characters (not shown)");
}

TEST(ConfigLimits, WrongNodeShapesAreConfigErrors) {
  const auto root =
      ConfigNode::Parse("a: {x: 1}\nb: [1, 2]\nc: 5\nn: 99999999999999999999\ne:\n", "s.yaml");
  EXPECT_EQ(error_of([&] { root["a"].size(); }), "s.yaml:1: a: expected a sequence, got a map");
  EXPECT_EQ(error_of([&] { root["a"].at(0); }), "s.yaml:1: a: expected a sequence, got a map");
  EXPECT_EQ(error_of([&] { root["a"].as_doubles(); }),
            "s.yaml:1: a: expected a sequence of numbers, got a map");
  EXPECT_EQ(error_of([&] { root["a"].as_string(); }), "s.yaml:1: a: expected a string, got a map");
  EXPECT_EQ(error_of([&] { root["b"].expect_keys({"x"}); }),
            "s.yaml:2: b: expected a map, got a sequence");
  EXPECT_EQ(error_of([&] { root["b"].keys(); }), "s.yaml:2: b: expected a map, got a sequence");
  EXPECT_EQ(error_of([&] { root["c"]["x"]; }), "s.yaml:3: c: expected a map, got a scalar");
  EXPECT_EQ(error_of([&] { root["c"].expect_keys({"x"}); }),
            "s.yaml:3: c: expected a map, got a scalar");
  EXPECT_EQ(error_of([&] { root["n"].as_int(); }),
            "s.yaml:4: n: expected an integer, got '99999999999999999999'");
  EXPECT_EQ(error_of([&] { root["b"].as_bool(); }),
            "s.yaml:2: b: expected true or false, got a sequence");
  EXPECT_EQ(error_of([&] { root["e"].expect_keys({"x"}); }), "no error");  // empty value
  // A key that is itself a sequence or a map.
  EXPECT_EQ(error_of([] { ConfigNode::Parse("? [1, 2]\n: x\n", "k.yaml"); }),
            "k.yaml:1: expected a plain key, got a sequence as a key");
  EXPECT_EQ(error_of([] { ConfigNode::Parse("a:\n  {x: 1}: y\n", "k.yaml"); }),
            "k.yaml:2: a: expected a plain key, got a map as a key");
}

}  // namespace
}  // namespace spidar::core
