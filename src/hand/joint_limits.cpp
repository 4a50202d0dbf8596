#include "spidar/hand/joint_limits.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

namespace spidar::hand {
namespace {

Status check(const Interval& r, const char* name, bool non_negative) {
  const auto deg = [](double rad) { return std::to_string(units::rad_to_deg(rad)); };
  if (!std::isfinite(r.lo) || !std::isfinite(r.hi)) {
    return Error{std::string("joint range ") + name + ": expected finite bounds"};
  }
  if (!(r.lo < r.hi)) {
    return Error{std::string("joint range ") + name + ": expected lo < hi, got [" + deg(r.lo) +
                 ", " + deg(r.hi) + "] deg"};
  }
  if (r.lo < -std::numbers::pi || r.hi > std::numbers::pi) {
    return Error{std::string("joint range ") + name + ": expected bounds within ±180 deg"};
  }
  if (non_negative && r.lo < 0.0) {
    return Error{std::string("joint range ") + name +
                 ": expected lo >= 0 (coupled joints flex only), got " + deg(r.lo) + " deg"};
  }
  return Ok{};
}

}  // namespace

Status validate_joint_ranges(const JointRanges& r) {
  for (const auto& s :
       {check(r.mcp_flexion, "mcp_flexion", false), check(r.mcp_abduction, "mcp_abduction", false),
        check(r.pip_flexion, "pip_flexion", true), check(r.dip_flexion, "dip_flexion", true),
        check(r.thumb_cmc_flexion, "thumb_cmc_flexion", false),
        check(r.thumb_cmc_abduction, "thumb_cmc_abduction", false),
        check(r.thumb_mcp_flexion, "thumb_mcp_flexion", true),
        check(r.thumb_ip_flexion, "thumb_ip_flexion", true)}) {
    if (!s.ok()) return s;
  }
  return Ok{};
}

ParamLimits parameter_limits(const JointRanges& r, Coupling coupling) {
  ParamLimits lim;
  auto set = [&](int i, double lo, double hi) {
    lim.lower[i] = lo;
    lim.upper[i] = hi;
  };
  auto distal = [&](int i, const Interval& penultimate, const Interval& last) {
    const double hi = std::min(last.hi, distal_for_penultimate(coupling, penultimate.hi));
    set(i, last.lo, std::max(hi, last.lo));
  };
  set(kThumbCmcFlexion, r.thumb_cmc_flexion.lo, r.thumb_cmc_flexion.hi);
  set(kThumbCmcAbduction, r.thumb_cmc_abduction.lo, r.thumb_cmc_abduction.hi);
  distal(kThumbIp, r.thumb_mcp_flexion, r.thumb_ip_flexion);
  for (const auto& d : {digit_params(kIndex), digit_params(kMiddle), digit_params(kRing),
                        digit_params(kLittle, true)}) {
    set(d.flexion, r.mcp_flexion.lo, r.mcp_flexion.hi);
    if (d.abduction >= 0) set(d.abduction, r.mcp_abduction.lo, r.mcp_abduction.hi);
    distal(d.distal, r.pip_flexion, r.dip_flexion);
  }
  return lim;
}

ParamLimits passive_limits(const ParamLimits& limits, const PassiveRange& passive) {
  ParamLimits out = limits;
  for (int f : {kIndex, kMiddle, kRing}) {
    const auto d = digit_params(f);
    out.lower[d.flexion] -= passive.mcp_extension;
    if (d.abduction >= 0) {
      out.lower[d.abduction] -= passive.mcp_abduction;
      out.upper[d.abduction] += passive.mcp_abduction;
    }
  }
  return out;
}

HandParams clamp_to_limits(const HandParams& params, const ParamLimits& limits) {
  HandParams out = params;
  for (int i = 0; i < kParamCount; ++i) {
    const double lo = limits.lower[i];
    const double hi = limits.upper[i];
    double v = out.q[i];
    if (std::isnan(v)) {
      if (std::isfinite(lo) && std::isfinite(hi)) {
        v = 0.5 * (lo + hi);
      } else if (std::isfinite(lo)) {
        v = lo;
      } else if (std::isfinite(hi)) {
        v = hi;
      } else {
        v = 0.0;
      }
    }
    out.q[i] = std::clamp(v, lo, hi);
  }
  return out;
}

bool within_limits(const HandParams& params, const ParamLimits& limits, double tol) {
  for (int i = 0; i < kParamCount; ++i) {
    const double v = params.q[i];
    if (!(v >= limits.lower[i] - tol && v <= limits.upper[i] + tol)) return false;
  }
  return true;
}

}  // namespace spidar::hand
