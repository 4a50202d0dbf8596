#pragma once
/// Fixed-capacity containers for the strings of one fingertip (one "point"). A point has
/// between 3 and kMaxStrings strings; these types never allocate, so the servo path can use them.
#include <span>

#include "spidar/core/types.hpp"

namespace spidar::strings {

/// Most strings tied to one point (SPIDAR-8: 3; SPIDAR-G: 4; room for 8).
inline constexpr int kMaxStrings = 8;

/// One value per string (lengths [m], tensions [N], ...).
using StringVec = SmallVec<kMaxStrings>;

/// 3×N matrix, one column per string (e.g. unit directions u_i).
using StringMat = Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::ColMajor, 3, kMaxStrings>;

/// Tension bounds of every string [N]. Strings only pull; t_min keeps them taut.
struct TensionLimits {
  double t_min = 0.35;
  double t_max = 30.0;
};

}  // namespace spidar::strings
