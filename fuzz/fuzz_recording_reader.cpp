// libFuzzer target for the recording reader (`make fuzz`). Also linked into test_session, which
// runs every file of fuzz/corpus/recording_reader through it.
//
// The first byte picks the file (modulo 6): 0 device.csv (the second byte gives its string count,
// 1 + byte % 32), 1 fingertips.csv, 2 frames.csv, 3 scene.csv, 4 fits.csv, 5 session.json; the
// rest is the file's text. Invariants checked on every input (a violation aborts with a message):
//   - the reader either returns or throws RecordingError, never anything else;
//   - an error message starts with the file's name and, for a CSV, a line number (`fuzz.csv:N`),
//     and is one line;
//   - what the reader accepts, written again by the writer's row functions, reads back and
//     writes again to the same text (the writer and the reader agree on every accepted row).
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <string_view>

#include "spidar/session/recording_reader.hpp"
#include "spidar/session/recording_writer.hpp"

namespace {

using namespace spidar::session;

[[noreturn]] void fail(const char* what, const std::string& detail = "") {
  std::fprintf(stderr, "fuzz_recording_reader: invariant violated: %s %s\n", what, detail.c_str());
  std::abort();
}

const std::string kName = "fuzz.csv";

/// Reads `text` as file kind `kind` and writes what it read back as text (header included).
std::string read_and_rewrite(int kind, int string_count, const std::string& text) {
  std::istringstream in(text);
  std::string out;
  switch (kind) {
    case 0:
      out = header_row(device_columns(string_count)) + "\n";
      read_device_csv(in, kName, string_count, [&](const DeviceCycleRecord& r) { out += device_row_text(r, string_count); });
      break;
    case 1:
      out = header_row(fingertip_columns()) + "\n";
      for (const auto& s : read_fingertips_csv(in, kName, -1)) out += fingertip_row_text(s);
      break;
    case 2:
      out = header_row(frame_columns()) + "\n";
      for (const auto& f : read_frames_csv(in, kName, -1)) out += frame_row_text(f);
      break;
    case 3: {
      out = header_row(scene_columns()) + "\n";
      std::vector<std::int64_t> frames;
      const auto poses = read_scene_csv(in, kName, &frames);
      for (std::size_t k = 0; k < poses.size(); ++k)
        for (std::size_t i = 0; i < poses[k].size(); ++i) out += scene_row_text(frames[k], i, poses[k][i]);
      break;
    }
    default:
      out = header_row(fit_columns()) + "\n";
      for (const auto& r : read_fits_csv(in, kName)) out += fit_row_text(r);
      break;
  }
  return out;
}

void check_message(const RecordingError& e, const std::string& name, bool csv) {
  const std::string m = e.what();
  if (m.rfind(name + ":", 0) != 0) fail("message starts with the file name:", m);
  if (csv && e.line() < 1) fail("a CSV error names a line:", m);
  if (m.find('\n') != std::string::npos) fail("message is one line:", m);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 2) return 0;
  const int kind = data[0] % 6;
  const int string_count = 1 + data[1] % 32;
  const std::string text(reinterpret_cast<const char*>(data) + 2, size - 2);
  if (kind == 5) {
    try {
      (void)parse_session_json(text, "session.json");
    } catch (const RecordingError& e) {
      check_message(e, "session.json", false);
    } catch (const std::exception& e) {
      fail("session.json: an exception other than RecordingError:", e.what());
    }
    return 0;
  }
  std::string once;
  try {
    once = read_and_rewrite(kind, string_count, text);
  } catch (const RecordingError& e) {
    check_message(e, kName, true);
    return 0;
  } catch (const std::exception& e) {
    fail("an exception other than RecordingError:", e.what());
  }
  try {
    const std::string twice = read_and_rewrite(kind, string_count, once);
    if (twice != once) fail("rows written again read back differently:\n", once + "\n---\n" + twice);
  } catch (const std::exception& e) {
    fail("rows the reader accepted, written again, are refused:", std::string(e.what()) + "\n" + once);
  }
  return 0;
}
