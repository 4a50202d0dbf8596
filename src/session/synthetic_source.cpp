// The simulated rig's camera: sim::CameraThread filming the scripted user's true hands.
#include "spidar/device/sample_interpolation.hpp"
#include "spidar/session/frame_source.hpp"
#include "spidar/sim/user_hands.hpp"

namespace spidar::session {
namespace {

class SyntheticSource final : public FrameSource {
 public:
  SyntheticSource(const vision::Camera& camera, const std::array<hand::HandModel, 2>& truth,
                  const sim::RubiksTask& task, device::SimulatedSpidar& dev, double fps,
                  std::uint64_t seed, bool bending_wrists)
      : camera_(camera), truth_(truth), task_(task), dev_(dev), fps_(fps), seed_(seed),
        bending_wrists_(bending_wrists) {}
  ~SyntheticSource() override { stop(); }

  Status prepare() override {
    if (thread_) return Ok{};
    truth_buf_.resize(1000);
    // The ground truth comes from the simulated device: where it holds the user's fingertips.
    sim::TruthAt truth_at = [this](std::int64_t t_ns, std::span<Vec3> out) {
      const device::SimulatedSpidar& dev = dev_;
      const std::size_t n = device::read_back_to(
          [&dev](device::FingertipSample* o, std::size_t max) { return dev.truth_samples(o, max); }, t_ns,
          std::span(truth_buf_));
      const auto s = device::interpolate_samples({truth_buf_.data(), n}, t_ns);
      if (!s) return sim::Truth::kNone;
      for (std::size_t f = 0; f < out.size() && f < 8; ++f)
        out[f] = device::fingertip_position(*s, static_cast<int>(f));
      // Newest first: exact once a sample at or after t_ns has come, else the newest held.
      return truth_buf_[0].t_ns >= t_ns ? sim::Truth::kExact : sim::Truth::kHeld;
    };
    sim::SyntheticCameraParams cp;
    cp.seed = seed_;
    if (bending_wrists_) cp.elbows_W = sim::user_elbows(task_);
    sim::CameraThreadParams ctp;
    ctp.fps = fps_;
    auto r = sim::CameraThread::prepare(camera_, truth_, cp, task_, truth_at, ctp);
    if (!r) return r.error();
    thread_ = std::move(r).value();
    return Ok{};
  }
  Status start(std::int64_t t0_ns) override {
    if (auto st = prepare(); !st) return st;
    thread_->begin(t0_ns);
    return Ok{};
  }
  bool take(CameraFrame* out) override {
    if (!thread_ || stopped_ || !thread_->take()) return false;
    out->filmed_hold = thread_->shared();
    const sim::FilmedFrame& f = *out->filmed_hold;
    out->bgr = f.frame.bgr;  // a header on the frame's image: valid while the frame is held
    out->t_exposure_ns = f.t_exposure_ns;
    out->filmed = &f;
    return true;
  }
  void wait_for_frame(std::int64_t deadline_ns) override {
    if (thread_ && !stopped_) thread_->wait_for_frame(deadline_ns);
  }
  bool ended() const override { return stopped_ && thread_ && !thread_->error().empty(); }
  std::string error() const override { return stopped_ && thread_ ? thread_->error() : std::string(); }
  std::uint64_t delivered() const override { return thread_ ? thread_->filmed() : 0; }
  std::uint64_t skipped() const override { return thread_ ? thread_->skipped() : 0; }
  void stop() override {
    if (thread_ && !stopped_) thread_->stop();
    stopped_ = true;
  }

 private:
  vision::Camera camera_;
  std::array<hand::HandModel, 2> truth_;
  const sim::RubiksTask& task_;
  device::SimulatedSpidar& dev_;
  double fps_;
  std::uint64_t seed_;
  bool bending_wrists_;
  std::vector<device::FingertipSample> truth_buf_;
  std::unique_ptr<sim::CameraThread> thread_;
  bool stopped_ = false;
};

}  // namespace

std::unique_ptr<FrameSource> make_synthetic_source(const vision::Camera& camera,
                                                   const std::array<hand::HandModel, 2>& truth,
                                                   const sim::RubiksTask& task,
                                                   device::SimulatedSpidar& dev, double fps,
                                                   std::uint64_t seed, bool bending_wrists) {
  return std::make_unique<SyntheticSource>(camera, truth, task, dev, fps, seed, bending_wrists);
}

}  // namespace spidar::session
