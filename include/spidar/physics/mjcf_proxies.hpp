#pragma once
/// Adding the fingertip proxies to a user's MJCF scene, through an XML parser (tinyxml2, the
/// parser MuJoCo itself reads MJCF with), never by searching the text: a `</worldbody>` inside a
/// comment, a CDATA section, a processing instruction or an attribute value is just text.
#include <cstddef>
#include <string>

#include "spidar/core/result.hpp"

namespace spidar::physics {

struct ProxyParams {
  int count = 8;             ///< one per device fingertip
  double radius = 0.008;     ///< [m]
  double mass = 0.01;        ///< [kg]; gravity is compensated
  double friction = 1.0;     ///< sliding friction against objects
  double torsional_friction = 0.002;  ///< [m]; keeps a pinched object from pivoting
};

/// The largest MJCF scene file we read [bytes] (its meshes and includes are MuJoCo's to read).
inline constexpr std::size_t kMaxSceneFileBytes = std::size_t{64} << 20;

/// `mjcf` re-printed with the proxy bodies `proxy_0..proxy_{n−1}` appended as the last children
/// of its one `<worldbody>` (a direct child of the root `<mujoco>`). `source` names the text in
/// messages (the scene's path). Errors, each `SOURCE[:LINE]: what (expected …)`:
///   - not XML (does not start with `<`; its content is not quoted),
///   - malformed XML: tinyxml2's error name and detail, at its line,
///   - a root element other than `<mujoco>`,
///   - no `<worldbody>`, or more than one (the second one's line and the first one's).
/// Line numbers in MuJoCo's messages about the returned text are those of the re-printed text,
/// not of `mjcf` (World::Load reports MuJoCo's errors against the original file).
Result<std::string> inject_proxies(const std::string& mjcf, const ProxyParams& proxy,
                                   const std::string& source = "MJCF text");

}  // namespace spidar::physics
