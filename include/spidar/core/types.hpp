#pragma once
/// Eigen aliases used across spidar. All quantities are SI (m, N, s, rad) unless a name says
/// otherwise.
#include <array>
#include <cstddef>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace spidar {

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;
using Vec4 = Eigen::Vector4d;
using Mat3 = Eigen::Matrix3d;
using Mat4 = Eigen::Matrix4d;
using Quat = Eigen::Quaterniond;
using VecX = Eigen::VectorXd;
using MatX = Eigen::MatrixXd;

/// A dynamically sized column vector that never allocates: at most `kMax` entries, stored inline.
/// For real-time paths (one entry per string, per joint).
template <int kMax>
using SmallVec = Eigen::Matrix<double, Eigen::Dynamic, 1, Eigen::ColMajor, kMax, 1>;

/// An array of N zero vectors or matrices (V: a fixed-size Eigen type). `std::array<Vec3, N> x{}`
/// does not zero them: Eigen's default constructor leaves its coefficients uninitialised, and
/// value-initialisation calls it. Use `std::array<Vec3, N> x = zeros<Vec3, N>();`.
template <class V, std::size_t N>
std::array<V, N> zeros() {
  std::array<V, N> a;
  a.fill(V::Zero());
  return a;
}

}  // namespace spidar
