#include "spidar/strings/calibration.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "spidar/strings/position.hpp"

namespace spidar::strings {

std::optional<Vec3> fingertip_from_counts(const FingerConfig& finger,
                                          std::span<const EncoderChannel> channels,
                                          std::span<const std::int64_t> counts) {
  const int n = finger.geometry.n;
  if (static_cast<int>(channels.size()) < n || static_cast<int>(counts.size()) < n) return std::nullopt;
  std::vector<double> lengths(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) lengths[i] = counts_to_length(channels[i], counts[i]);
  const auto est = solve_position(finger.geometry, lengths);
  if (!est) return std::nullopt;
  return est->p_WF;
}

Result<std::vector<EncoderChannel>> pole_calibrate(const PointGeometry& g,
                                                   std::span<const EncoderChannel> channels,
                                                   std::span<const std::int64_t> counts,
                                                   const Vec3& p_W_pole) {
  if (static_cast<int>(channels.size()) != g.n || static_cast<int>(counts.size()) != g.n) {
    return Error{"pole calibration: expected " + std::to_string(g.n) +
                 " channels and counts, got " + std::to_string(channels.size()) + " and " +
                 std::to_string(counts.size())};
  }
  if (!p_W_pole.allFinite()) return Error{"pole calibration: pole position is not finite"};
  std::vector<EncoderChannel> out(channels.begin(), channels.end());
  for (int i = 0; i < g.n; ++i) {
    const double l = (g.p_WA[i] - p_W_pole).norm();
    out[i].length_at_zero =
        l - out[i].sign * out[i].metres_per_count * static_cast<double>(counts[i]);
  }
  return out;
}

Result<std::vector<StringFit>> fit_multipoint(const PointGeometry& g,
                                              std::span<const JigSample> samples) {
  if (samples.size() < 2) {
    return Error{"multi-point calibration: expected at least 2 jig samples, got " +
                 std::to_string(samples.size())};
  }
  for (std::size_t j = 0; j < samples.size(); ++j) {
    if (static_cast<int>(samples[j].counts.size()) != g.n) {
      return Error{"multi-point calibration: sample " + std::to_string(j) + ": expected " +
                   std::to_string(g.n) + " counts, got " +
                   std::to_string(samples[j].counts.size())};
    }
    if (!samples[j].p_WF.allFinite()) {
      return Error{"multi-point calibration: sample " + std::to_string(j) +
                   ": position is not finite"};
    }
  }
  const auto m = static_cast<double>(samples.size());
  std::vector<StringFit> fits(g.n);
  for (int i = 0; i < g.n; ++i) {
    // Centred linear regression of length on count (numerically safe for large counts).
    double c_mean = 0, l_mean = 0;
    for (const auto& s : samples) {
      c_mean += static_cast<double>(s.counts[i]);
      l_mean += (g.p_WA[i] - s.p_WF).norm();
    }
    c_mean /= m;
    l_mean /= m;
    double scc = 0, scl = 0;
    for (const auto& s : samples) {
      const double dc = static_cast<double>(s.counts[i]) - c_mean;
      scc += dc * dc;
      scl += dc * ((g.p_WA[i] - s.p_WF).norm() - l_mean);
    }
    if (scc < 1.0 * m) {  // counts spread by less than about one count
      return Error{"multi-point calibration: string " + std::to_string(i) +
                   ": counts do not vary between jig points; expected samples that change "
                   "this string's length"};
    }
    const double slope = scl / scc;  // s_i · k_i
    StringFit& fit = fits[i];
    fit.channel.sign = slope >= 0 ? 1 : -1;
    fit.channel.metres_per_count = std::abs(slope);
    fit.channel.length_at_zero = l_mean - slope * c_mean;
    double sum2 = 0;
    for (const auto& s : samples) {
      const double r = counts_to_length(fit.channel, s.counts[i]) - (g.p_WA[i] - s.p_WF).norm();
      sum2 += r * r;
      fit.residual_max = std::max(fit.residual_max, std::abs(r));
    }
    fit.residual_rms = std::sqrt(sum2 / m);
  }
  return fits;
}

Result<double> position_error_rms(const PointGeometry& g,
                                  std::span<const EncoderChannel> true_channels,
                                  std::span<const EncoderChannel> calibrated,
                                  std::span<const Vec3> p_W_test) {
  if (static_cast<int>(true_channels.size()) != g.n ||
      static_cast<int>(calibrated.size()) != g.n) {
    return Error{"position_error_rms: expected " + std::to_string(g.n) + " channels"};
  }
  if (p_W_test.empty()) return Error{"position_error_rms: no test points"};
  double sum2 = 0.0;
  for (const Vec3& p : p_W_test) {
    const StringVec l_true = string_lengths(g, p);
    StringVec l(g.n);
    for (int i = 0; i < g.n; ++i) {
      l[i] = counts_to_length(calibrated[i], length_to_counts(true_channels[i], l_true[i]));
    }
    auto est = solve_position(g, std::span<const double>(l.data(), g.n));
    if (!est) return est.error();
    sum2 += (est->p_WF - p).squaredNorm();
  }
  return std::sqrt(sum2 / static_cast<double>(p_W_test.size()));
}

std::vector<Vec3> jig_grid(const Vec3& c, double spacing, int n) {
  std::vector<Vec3> out;
  const double h = 0.5 * (n - 1);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k) out.push_back(c + spacing * Vec3(i - h, j - h, k - h));
  return out;
}

}  // namespace spidar::strings
