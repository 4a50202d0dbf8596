#include "spidar/physics/mjcf_proxies.hpp"

#include <tinyxml2.h>

#include <cstdio>
#include <string_view>

#include "spidar/core/file_read.hpp"

namespace spidar::physics {
namespace {

/// `v` with 9 significant digits, as MJCF attribute text.
std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

/// True if, after an optional UTF-8 byte-order mark and white space, the text starts with '<'.
bool looks_like_xml(std::string_view text) {
  if (text.starts_with("\xEF\xBB\xBF")) text.remove_prefix(3);
  const std::size_t k = text.find_first_not_of(" \t\r\n");
  return k != std::string_view::npos && text[k] == '<';
}

/// tinyxml2's detail of a parse error ("XMLElement name=body"), shortened and with control
/// characters escaped: it can quote a little of the file, which is XML, not a stranger's file.
std::string parse_detail(const tinyxml2::XMLDocument& doc) {
  std::string s = doc.ErrorStr() ? doc.ErrorStr() : "";
  // ErrorStr() is "Error=NAME ErrorID=N (0xN) Line number=L[: detail]": keep the detail.
  const std::size_t colon = s.find(": ");
  s = colon == std::string::npos ? std::string() : s.substr(colon + 2);
  if (s.size() > 80) s = s.substr(0, 80) + "…";
  return core::printable_for_message(s);
}

tinyxml2::XMLElement* add_child(tinyxml2::XMLDocument& doc, tinyxml2::XMLElement* parent,
                                const char* name) {
  tinyxml2::XMLElement* e = doc.NewElement(name);
  parent->InsertEndChild(e);
  return e;
}

/// One proxy body, parked below the scene until placed. contype 2 / conaffinity 1: proxies touch
/// the scene (default contype 1) but not each other. Three slide joints: a fingertip proxy
/// translates but does not roll (a rolling sphere would climb a grasped object instead of
/// lifting it).
void add_proxy(tinyxml2::XMLDocument& doc, tinyxml2::XMLElement* worldbody, int i,
               const ProxyParams& p) {
  const std::string name = "proxy_" + std::to_string(i);
  tinyxml2::XMLElement* body = add_child(doc, worldbody, "body");
  body->SetAttribute("name", name.c_str());
  body->SetAttribute("pos", (num(0.05 * i) + " 0 -5").c_str());
  static constexpr const char* kAxes[3][2] = {{"_x", "1 0 0"}, {"_y", "0 1 0"}, {"_z", "0 0 1"}};
  for (const auto& [suffix, axis] : kAxes) {
    tinyxml2::XMLElement* joint = add_child(doc, body, "joint");
    joint->SetAttribute("name", (name + suffix).c_str());
    joint->SetAttribute("type", "slide");
    joint->SetAttribute("axis", axis);
  }
  tinyxml2::XMLElement* geom = add_child(doc, body, "geom");
  geom->SetAttribute("name", (name + "_geom").c_str());
  geom->SetAttribute("type", "sphere");
  geom->SetAttribute("size", num(p.radius).c_str());
  geom->SetAttribute("mass", num(p.mass).c_str());
  geom->SetAttribute("contype", "2");
  geom->SetAttribute("conaffinity", "1");
  geom->SetAttribute("condim", "4");
  geom->SetAttribute("friction",
                     (num(p.friction) + " " + num(p.torsional_friction) + " 0.0001").c_str());
  geom->SetAttribute("rgba", "0.9 0.3 0.3 0.6");
}

}  // namespace

Result<std::string> inject_proxies(const std::string& mjcf, const ProxyParams& p,
                                   const std::string& source) {
  const std::string where = core::printable_for_message(source);
  if (!looks_like_xml(mjcf)) {
    return Error{where + ": not an XML file (expected an MJCF scene: <mujoco>…</mujoco>)"};
  }
  tinyxml2::XMLDocument doc(/*processEntities=*/true, tinyxml2::PRESERVE_WHITESPACE);
  if (doc.Parse(mjcf.data(), mjcf.size()) != tinyxml2::XML_SUCCESS) {
    const std::string detail = parse_detail(doc);
    return Error{where + ":" + std::to_string(doc.ErrorLineNum()) + ": malformed XML: " +
                 doc.ErrorName() + (detail.empty() ? "" : " (" + detail + ")") +
                 " (expected a well-formed MJCF scene)"};
  }
  tinyxml2::XMLElement* root = doc.RootElement();
  if (root == nullptr) {
    return Error{where + ": no root element (expected an MJCF scene: <mujoco>…</mujoco>)"};
  }
  if (std::string_view(root->Name()) != "mujoco") {
    return Error{where + ":" + std::to_string(root->GetLineNum()) + ": the root element is <" +
                 core::printable_for_message(root->Name()) + ">; expected <mujoco>"};
  }
  tinyxml2::XMLElement* worldbody = root->FirstChildElement("worldbody");
  if (worldbody == nullptr) {
    return Error{where + ": no <worldbody> in <mujoco> to add the fingertip proxies to; expected "
                         "one <worldbody> element in the scene file itself (not only in an "
                         "<include>d file)"};
  }
  if (const tinyxml2::XMLElement* second = worldbody->NextSiblingElement("worldbody")) {
    return Error{where + ":" + std::to_string(second->GetLineNum()) +
                 ": a second <worldbody> (the first is at line " +
                 std::to_string(worldbody->GetLineNum()) +
                 "); expected exactly one, to add the fingertip proxies to"};
  }
  if (p.count > 0) worldbody->InsertEndChild(doc.NewComment(" spidar-mr fingertip proxies "));
  for (int i = 0; i < p.count; ++i) add_proxy(doc, worldbody, i, p);

  tinyxml2::XMLPrinter printer;
  doc.Print(&printer);
  // CStrSize() counts the terminating NUL.
  return std::string(printer.CStr(), static_cast<std::size_t>(printer.CStrSize() - 1));
}

}  // namespace spidar::physics
