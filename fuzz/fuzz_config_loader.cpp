// libFuzzer target for the config loader (`make fuzz`): core::ConfigNode::Parse, every typed
// accessor on every node, and the device config parser (strings::parse_device_config) on top.
// Also linked into test_strings_fuzz, which runs every file of fuzz/corpus/config_loader through it.
//
// Invariants checked on every input (a violation aborts with a message):
//   - loading either succeeds or throws ConfigError (or another SpidarError from a typed parser),
//     never anything else (no yaml-cpp exception, no std::out_of_range, no crash);
//   - an error message starts with the file's name (`fuzz.yaml:`) and is one line.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "spidar/core/config.hpp"
#include "spidar/strings/device_config.hpp"

namespace {

using spidar::core::ConfigError;
using spidar::core::ConfigNode;

const std::string kName = "fuzz.yaml";

[[noreturn]] void fail(const char* what, const std::string& detail) {
  std::fprintf(stderr, "fuzz_config_loader: invariant violated: %s %s\n", what, detail.c_str());
  std::abort();
}

void check_message(const std::exception& e) {
  const std::string m = e.what();
  if (m.rfind(kName, 0) != 0) fail("message starts with the file name:", m);
  if (m.find('\n') != std::string::npos) fail("message is one line:", m);
}

/// Calls every accessor on `node` and its children; ConfigErrors of the accessors are expected.
void walk(const ConfigNode& node, int depth) {
  if (depth > 100) fail("nesting deeper than the loader allows", node.path());
  (void)node.line();
  if (node.is_map()) {
    for (const std::string& key : node.keys()) {
      walk(node[key], depth + 1);
      (void)node.find(key);
    }
    try {
      node.expect_keys({"name", "fingers"});
    } catch (const ConfigError& e) {
      check_message(e);
    }
  } else if (node.is_sequence()) {
    for (std::size_t i = 0; i < node.size(); ++i) walk(node.at(i), depth + 1);
  }
  auto attempt = [](auto&& accessor) {
    try {
      accessor();
    } catch (const ConfigError& e) {
      check_message(e);
    }
  };
  attempt([&] { (void)node.as_double(); });
  attempt([&] { (void)node.as_int(); });
  attempt([&] { (void)node.as_bool(); });
  attempt([&] { (void)node.as_string(); });
  attempt([&] { (void)node.as_vec3(); });
  attempt([&] { (void)node.as_doubles(); });
  attempt([&] { (void)node.size(); });
  attempt([&] { (void)node["device"]; });
  attempt([&] { (void)node.get_double("rate_hz", 1.0); });
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const ConfigNode root = ConfigNode::Parse(text, kName);
    walk(root, 0);
    (void)spidar::strings::parse_device_config(root);
  } catch (const spidar::SpidarError& e) {  // ConfigError and the typed parsers' errors
    check_message(e);
  } catch (const std::exception& e) {
    fail("an exception other than a SpidarError:", e.what());
  }
  return 0;
}
