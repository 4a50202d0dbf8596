#pragma once
/// A recording (`spidar-mr run --record DIR`, read back by read_recording) played back as a rig:
/// its camera gives the recorded frames one after the other, each with the fingertip sample and
/// the scene poses the live registration used, so a Session fits them through the same
/// pipeline::FramePipeline as the live run (docs/recording.md, "What replay reproduces"). It has
/// no device to drive: the session runs no servo loop and no physics for it.
#include <memory>
#include <string>

#include "spidar/session/recording_reader.hpp"
#include "spidar/session/rig.hpp"

namespace spidar::session {

class RecordingRig final : public Rig {
 public:
  /// Plays `recording` back with frames of `width`×`height` px; a frame that does not decode or
  /// has another size is skipped and counted (decode_errors). Throws SpidarError naming the
  /// video if a video store cannot be opened.
  RecordingRig(Recording recording, int width, int height);
  ~RecordingRig() override;
  bool plays_back() const override { return true; }
  /// SpidarError: a recording has no device to drive.
  device::Device& device() override;
  /// An empty layout: the recorded fingertips were solved live.
  const strings::DeviceConfig& device_config() const override { return no_layout_; }
  FrameSource& camera() override;
  std::string name() const override { return "recording " + recording_.dir; }

  const Recording& recording() const { return recording_; }
  /// The frames.csv row of the frame the camera gave last (valid during a FrameSink's on_frame).
  std::size_t row() const;
  /// Frames skipped so far because their image did not decode or had another size.
  int decode_errors() const;
  /// The first of them, with its file and what was wrong ("frame 10 (frames/000010.png): a PNG
  /// of 30000x30000 px, expected a 640x480 px image"); empty if none.
  const std::string& first_decode_error() const;

 private:
  class Source;
  Recording recording_;
  strings::DeviceConfig no_layout_;
  std::unique_ptr<Source> source_;
};

}  // namespace spidar::session
