// The recording reader's fuzz corpus as a test: every file of fuzz/corpus/recording_reader goes
// through the entry point libFuzzer calls (fuzz/fuzz_recording_reader.cpp), which aborts on an
// invariant violation (an exception other than RecordingError, a message without FILE:LINE, or
// rows that do not read back the same after writing them again).
#include "fuzz_corpus.hpp"

namespace {

TEST(FuzzCorpus, RecordingReaderCorpusPassesTheFuzzInvariants) {
  // Seeds: each CSV and session.json, valid and damaged (fuzz/make_recording_seeds.py).
  spidar::test::replay_fuzz_corpus(SPIDAR_FUZZ_CORPUS, 40);
}

}  // namespace
