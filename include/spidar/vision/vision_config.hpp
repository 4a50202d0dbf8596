#pragma once
/// configs/vision.yaml: the image-processing parameters (camera geometry is camera.yaml).
///
///   chroma_key: { ... }   # ChromaKeyParams, every key optional (chroma_key.hpp)
///   bracelet: { ... }     # BraceletParams, every key optional (bracelet.hpp)
#include <string>

#include "spidar/vision/bracelet.hpp"
#include "spidar/vision/chroma_key.hpp"

namespace spidar::vision {

struct VisionConfig {
  ChromaKeyParams chroma_key;
  BraceletParams bracelet;
  std::string source;
};

/// Throws core::ConfigError naming file:line: key.
VisionConfig parse_vision_config(const core::ConfigNode& root);
VisionConfig load_vision_config(const std::string& path);

}  // namespace spidar::vision
