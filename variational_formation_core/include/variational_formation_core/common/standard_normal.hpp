#pragma once

#include <cmath>
#include <random>

namespace vf {

/**
 * Random numbers that depend only on the seed. std::mt19937_64's output sequence is fixed by the
 * C++ standard but the std distributions are not, so the two used here are written out.
 */

/// Uniform in [0, 1): the top 53 bits of one draw, scaled by 2^-53.
inline double uniformUnit(std::mt19937_64& engine) {
  return static_cast<double>(engine() >> 11) * 0x1.0p-53;
}

/// Standard normal samples by the Box-Muller transform; the second value of each pair is kept
/// for the next call.
class StandardNormal {
 public:
  double operator()(std::mt19937_64& engine) {
    if (hasSpare_) {
      hasSpare_ = false;
      return spare_;
    }
    const double u1 = 1.0 - uniformUnit(engine);  // (0, 1]: log(u1) is finite
    const double u2 = uniformUnit(engine);
    const double radius = std::sqrt(-2.0 * std::log(u1));
    const double angle = 6.283185307179586 * u2;  // 2 pi u2
    spare_ = radius * std::sin(angle);
    hasSpare_ = true;
    return radius * std::cos(angle);
  }

 private:
  double spare_ = 0.0;
  bool hasSpare_ = false;
};

}  // namespace vf
