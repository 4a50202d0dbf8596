#include "spidar/session/recording_schema.hpp"

namespace spidar::session {

std::vector<std::string> sample_columns() {
  std::vector<std::string> c = {"faults", "consistent", "finger_count"};
  for (const char* what : {"p", "f"})
    for (int f = 0; f < device::kMaxFingers; ++f)
      for (const char* axis : {"x", "y", "z"}) c.push_back(what + std::to_string(f) + axis);
  return c;
}

std::vector<std::string> device_columns(int string_count) {
  std::vector<std::string> c = {"seq", "host_time_ns", "device_time_us", "status", "repeats"};
  for (int i = 0; i < string_count; ++i) c.push_back("count" + std::to_string(i));
  for (int i = 0; i < string_count; ++i) c.push_back("command" + std::to_string(i));
  return c;
}

std::vector<std::string> fingertip_columns() {
  std::vector<std::string> c = {"t_ns", "cycle"};
  for (auto& s : sample_columns()) c.push_back(std::move(s));
  return c;
}

std::vector<std::string> servo_output_columns(int string_count) {
  std::vector<std::string> c;
  for (int i = 0; i < string_count; ++i) c.push_back("tension" + std::to_string(i));
  for (int i = 0; i < string_count; ++i) c.push_back("motor" + std::to_string(i));
  return c;
}

std::vector<std::string> frame_columns() {
  std::vector<std::string> c = {"frame", "t_exposure_ns", "image"};
  for (auto& s : sample_columns()) c.push_back(std::move(s));
  return c;
}

std::vector<std::string> scene_columns() { return {"frame", "shape", "px", "py", "pz", "qw", "qx", "qy", "qz"}; }

std::vector<std::string> fit_columns() {
  std::vector<std::string> c = {"frame",      "hand",       "iterations", "converged", "finite", "cost_initial",
                                "cost_final", "fingertip",  "wrist",      "joint_ball", "silhouette", "prior"};
  for (int i = 0; i < hand::kPaperParamCount; ++i) c.push_back("q" + std::to_string(i));
  return c;
}

std::vector<std::string> fit_size_columns() { return {"length_m", "width_m"}; }

std::string header_row(const std::vector<std::string>& columns) {
  std::string h;
  for (const auto& c : columns) h += (h.empty() ? "" : ",") + c;
  return h;
}

std::string_view frame_store_name(FrameStore store) {
  switch (store) {
    case FrameStore::kVideo: return "video";
    case FrameStore::kMjpg: return "mjpg";
    case FrameStore::kPng: return "png";
  }
  return "video";
}

bool parse_frame_store(std::string_view name, FrameStore* store) {
  for (FrameStore s : {FrameStore::kVideo, FrameStore::kMjpg, FrameStore::kPng}) {
    if (frame_store_name(s) == name) {
      *store = s;
      return true;
    }
  }
  return false;
}

}  // namespace spidar::session
