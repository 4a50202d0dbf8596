// The fuzz target's regression corpus as a test: every file of fuzz/corpus/frame_decoder goes
// through the same entry point libFuzzer calls (fuzz/fuzz_frame_decoder.cpp), which aborts on an
// invariant violation.
#include "fuzz_corpus.hpp"

namespace {

TEST(FuzzCorpus, FrameDecoderCorpusPassesTheFuzzInvariants) {
  spidar::test::replay_fuzz_corpus(SPIDAR_FUZZ_CORPUS, 24);  // the seed corpus has a few dozen files
}

}  // namespace
