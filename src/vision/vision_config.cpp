#include "spidar/vision/vision_config.hpp"

namespace spidar::vision {

VisionConfig parse_vision_config(const core::ConfigNode& root) {
  root.expect_keys({"chroma_key", "bracelet"});
  VisionConfig out;
  out.source = root.file();
  if (auto n = root.find("chroma_key")) out.chroma_key = parse_chroma_key_params(*n);
  if (auto n = root.find("bracelet")) out.bracelet = parse_bracelet_params(*n);
  return out;
}

VisionConfig load_vision_config(const std::string& path) {
  return parse_vision_config(core::ConfigNode::LoadFile(path));
}

}  // namespace spidar::vision
