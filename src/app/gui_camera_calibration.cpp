#include "gui_camera_calibration.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>

#include "spidar/core/atomic_write.hpp"
#include "spidar/core/clock.hpp"
#include "spidar/core/file_write.hpp"
#include "spidar/strings/calibration.hpp"
#include "spidar/vision/camera_config.hpp"

namespace spidar::app {

void CameraCalibrationPanel::draw(session::LiveSession& s) {
  const strings::DeviceConfig& cfg = s.device_config();
  if (finger_ < 0) {  // the right index finger by default: the one a person points with
    finger_ = 0;
    for (std::size_t f = 0; f < cfg.fingers.size(); ++f)
      if (cfg.fingers[f].name == "right_index") finger_ = static_cast<int>(f);
  }
  ImGui::TextWrapped(
      "Touch a marker spot with the fingertip cap and hold still; then click the cap in the "
      "view. Three markers: the paper's method, with each marker's measured distance from the "
      "camera centre. Four or more: PnP from the clicks alone.");
  std::vector<const char*> names;
  for (const auto& f : cfg.fingers) names.push_back(f.name.c_str());
  if (ImGui::Combo("finger", &finger_, names.data(), static_cast<int>(names.size())) || !cal_) {
    cal_ = std::make_unique<vision::MarkerCalibration>(s.camera(),
                                                       cfg.fingers[finger_].name + " fingertip cap");
    check_.reset();
    solution_.reset();
  }
  if (!counts_)
    counts_ = std::make_unique<device::UnwrappedCounts>(cfg.string_count(), cfg.counter_bits);
  // Every reading the GUI sees is unwrapped, as the servo cycle does, so counts stay continuous.
  const auto rec = s.newest_device_cycle();
  if (rec) counts_->update(rec->reading);
  vision::MarkerCalibration& cal = *cal_;
  const strings::FingerConfig& fc = cfg.fingers[finger_];
  if (!check_ && !cal.pending()) {
    if (ImGui::Button("Touch next marker")) {
      strings::StabilityParams p;
      p.near_m = 1e9;  // the markers may be anywhere in the workspace
      check_ = std::make_unique<strings::StabilityCheck>(fc, Vec3::Zero(), p);
      message_.clear();
    }
  }
  if (check_) {
    if (rec) {
      check_->update(core::ns_to_s(rec->reading.host_time_ns),
                     counts_->counts(cfg.first_string(finger_), fc.geometry.n));
    }
    if (check_->ready()) {
      // The marker's world position from the mean counts; a failed position (inconsistent
      // strings) needs a new touch.
      if (const auto p_W = strings::fingertip_from_counts(fc, check_->sample())) {
        if (auto st = cal.touched(*p_W, check_->spread_m()); !st) message_ = st.error().message;
      } else {
        message_ = "the strings of " + fc.name + " gave no position: touch the marker again";
      }
      check_.reset();
    } else {
      ImGui::Text("m%zu: hold the %s cap still on the marker", cal.markers().size() + 1, names[finger_]);
      ImGui::ProgressBar(static_cast<float>(check_->held_s() / check_->params().hold_s),
                         ImVec2(-1, 0), "holding still");
      ImGui::Text("strings moving %.2f mm", check_->spread_m() * 1e3);
    }
  }
  if (const vision::CapturedMarker* p = cal.pending()) {
    ImGui::TextColored(ImVec4(1, 0.9f, 0.2f, 1), "%s at (%.3f, %.3f, %.3f) m: click the cap in the view",
                       p->name.c_str(), p->p_W.x(), p->p_W.y(), p->p_W.z());
  }
  if (!cal.markers().empty() && ImGui::BeginTable("markers", 4, ImGuiTableFlags_SizingStretchProp)) {
    ImGui::TableSetupColumn("marker");
    ImGui::TableSetupColumn("world [m]");
    ImGui::TableSetupColumn("pixel");
    ImGui::TableSetupColumn("range [m]");
    ImGui::TableHeadersRow();
    for (std::size_t i = 0; i < cal.markers().size(); ++i) {
      const vision::CapturedMarker& m = cal.markers()[i];
      ImGui::TableNextRow();
      ImGui::TableSetColumnIndex(0);
      ImGui::TextUnformatted(m.name.c_str());
      ImGui::TableSetColumnIndex(1);
      ImGui::Text("%.3f %.3f %.3f", m.p_W.x(), m.p_W.y(), m.p_W.z());
      ImGui::TableSetColumnIndex(2);
      ImGui::Text("%.1f %.1f", m.uv->x(), m.uv->y());
      ImGui::TableSetColumnIndex(3);
      double r = m.range_m;
      ImGui::PushID(static_cast<int>(i));
      ImGui::SetNextItemWidth(-1);
      if (ImGui::InputDouble("##range", &r, 0.001, 0.01, "%.4f") && r != m.range_m) {
        if (auto st = cal.set_range(i, r); !st) message_ = st.error().message;
        solution_.reset();
      }
      ImGui::PopID();
    }
    ImGui::EndTable();
  }
  if ((cal.pending() || !cal.markers().empty()) && ImGui::Button("Remove last")) {
    cal.remove_last();
    solution_.reset();
  }
  if (cal.markers().size() >= 3) {
    ImGui::SameLine();
    if (ImGui::Button(cal.markers().size() == 3 ? "Solve (three markers)" : "Solve (PnP)")) {
      auto r = cal.solve();
      if (r) {
        solution_ = *r;
        message_.clear();
      } else {
        solution_.reset();
        message_ = r.error().message;
      }
    }
  }
  if (solution_) {
    const auto& e = solution_->extrinsics;
    char residual[48];
    if (e.rms_px) std::snprintf(residual, sizeof residual, "%.2f px", *e.rms_px);
    else std::snprintf(residual, sizeof residual, "%.2f mm", e.rms_m.value_or(0) * 1e3);
    ImGui::Text("%s: residual %s; camera moved %.1f mm, turned %.2f deg", e.method.c_str(), residual,
                solution_->moved_m * 1e3, solution_->turned_deg);
    // Markers that disagree (a click off the cap, a range misread): say so before writing.
    if (e.rms_px.value_or(0) > 2.0 || e.rms_m.value_or(0) > 0.005)
      ImGui::TextColored(ImVec4(1, 0.35f, 0.3f, 1),
                         "the markers disagree: check the clicks (on the cap) and the ranges");
    const std::string& path = s.config().camera_calibration;
    if (ImGui::Button("Write to the camera file")) {
      try {
        // The file's own intrinsics (the session may scale them to its image size), new pose.
        const vision::CameraFile file = vision::load_camera_file(path);
        vision::CalibrationNotes notes = file.calibration;
        notes.method = (notes.intrinsics_rms_px ? "chessboard + " : "") + e.method + " (GUI, fingertip caps)";
        notes.extrinsics_rms_px = e.rms_px;
        notes.extrinsics_rms_m = e.rms_m;
        const std::string backup = core::keep_previous_version(path);
        if (auto st = vision::save_camera_file(path, vision::Camera(file.camera.intrinsics(), e.X_CW), notes); !st)
          throw SpidarError(st.error().message);
        const std::string markers = path + ".markers.yaml";
        core::keep_previous_version(markers);
        core::write_file_atomic(markers, cal.markers_yaml());
        message_ = "wrote " + path + " (previous: " + (backup.empty() ? "none" : backup) + ") and " + markers +
                   "; restart run to use it";
      } catch (const std::exception& ex) {
        message_ = ex.what();
      }
    }
  }
  if (!message_.empty()) ImGui::TextWrapped("%s", message_.c_str());
}

void CameraCalibrationPanel::on_view(const session::LiveSession& s, const ImVec2& image_min, float scale) {
  if (!cal_ || scale <= 0) return;
  ImDrawList* dl = ImGui::GetWindowDrawList();
  auto screen = [&](const Vec2& uv) {
    return ImVec2(image_min.x + static_cast<float>(uv.x()) * scale, image_min.y + static_cast<float>(uv.y()) * scale);
  };
  for (const vision::CapturedMarker& m : cal_->markers()) {
    dl->AddCircle(screen(*m.uv), 6, IM_COL32(60, 255, 60, 255), 16, 2);
    dl->AddText(ImVec2(screen(*m.uv).x + 8, screen(*m.uv).y - 8), IM_COL32(60, 255, 60, 255), m.name.c_str());
  }
  if (const vision::CapturedMarker* p = cal_->pending()) {
    // Where the present calibration sees the sampled fingertip: a hint for the click.
    dl->AddCircle(screen(s.camera().project(p->p_W)), 10, IM_COL32(255, 230, 50, 255), 16, 1.5f);
    if (ImGui::IsItemClicked(ImGuiMouseButton_Left)) {
      const ImVec2 mouse = ImGui::GetIO().MousePos;
      const Vec2 uv((mouse.x - image_min.x) / scale, (mouse.y - image_min.y) / scale);
      if (auto st = cal_->set_pixel(uv); !st) message_ = st.error().message;
      solution_.reset();
    }
  }
}

}  // namespace spidar::app
