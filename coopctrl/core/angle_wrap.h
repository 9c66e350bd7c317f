// An angle wrapped into [-pi, pi) as Python computes it: (e + pi) mod 2 pi - pi with Python's modulo (the result
// has the sign of the divisor), the arithmetic the control laws' and pre-flight's angle errors share.
#pragma once

#include <cmath>

namespace coopctrl {

constexpr double PI = 3.141592653589793;

/// a mod b with Python's sign convention (the result has the sign of b).
inline double python_mod(double a, double b) noexcept {
    double m = std::fmod(a, b);
    if (m != 0.0) {
        if ((b < 0.0) != (m < 0.0)) m += b;
    } else {
        m = std::copysign(0.0, b);
    }
    return m;
}

/// e wrapped into [-pi, pi) [rad]: (e + pi) mod 2 pi - pi.
inline double wrap_angle(double e) noexcept { return python_mod(e + PI, 2.0 * PI) - PI; }

}  // namespace coopctrl
