// The config loader's fuzz corpus as a test: every file of fuzz/corpus/config_loader goes through
// the entry point libFuzzer calls (fuzz/fuzz_config_loader.cpp: ConfigNode::Parse, every accessor,
// parse_device_config), which aborts on an invariant violation (an exception other than a
// SpidarError, a message that does not start with the file name or spans lines).
#include "fuzz_corpus.hpp"

namespace {

TEST(FuzzCorpus, ConfigLoaderCorpusPassesTheFuzzInvariants) {
  // Seeds: configs/*.yaml and small damaged YAML (fuzz/make_recording_seeds.py).
  spidar::test::replay_fuzz_corpus(SPIDAR_FUZZ_CORPUS, 12);
}

}  // namespace
