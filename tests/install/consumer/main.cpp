// Locates a fingertip from three string lengths and displays a force with spidar::strings.
#include <cstdio>
#include <vector>

#include "spidar/strings/position.hpp"
#include "spidar/strings/tension.hpp"

int main() {
  using namespace spidar;
  const std::vector<Vec3> A = {Vec3(-0.2, -0.2, 0.2), Vec3(0.2, -0.2, 0.2), Vec3(0.0, 0.2, 0.2)};
  const auto g = strings::make_point_geometry(A, Vec3::Zero()).value();
  const Vec3 p(0.01, 0.02, -0.03);
  const std::vector<double> l = {(A[0] - p).norm(), (A[1] - p).norm(), (A[2] - p).norm()};
  const auto est = strings::solve_position(g, l).value();
  const auto sol = strings::solve_tensions(g, est.p_WF, Vec3(0, 0, 2.0), {0.35, 17.0}).value();
  std::printf("position error %.3g m, force z %.3f N\n", (est.p_WF - p).norm(), sol.f_displayed.z());
  return (est.p_WF - p).norm() < 1e-9 && sol.reachable ? 0 : 1;
}
