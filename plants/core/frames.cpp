#include "plants/core/frames.h"

#include <cmath>

namespace plants {

void rotation_vector(const double* M, double* out) noexcept {
    const double m00 = M[0], m01 = M[1], m02 = M[2];
    const double m10 = M[3], m11 = M[4], m12 = M[5];
    const double m20 = M[6], m21 = M[7], m22 = M[8];
    const double tr = m00 + m11 + m22;
    double w, x, y, z;
    if (tr >= m00 && tr >= m11 && tr >= m22) {
        w = 1.0 + tr;
        x = m21 - m12;
        y = m02 - m20;
        z = m10 - m01;
    } else if (m00 >= m11 && m00 >= m22) {
        x = 1.0 + 2.0 * m00 - tr;
        y = m01 + m10;
        z = m02 + m20;
        w = m21 - m12;
    } else if (m11 >= m22) {
        x = m01 + m10;
        y = 1.0 + 2.0 * m11 - tr;
        z = m12 + m21;
        w = m02 - m20;
    } else {
        x = m02 + m20;
        y = m12 + m21;
        z = 1.0 + 2.0 * m22 - tr;
        w = m10 - m01;
    }
    double norm = std::sqrt(w * w + x * x + y * y + z * z);
    if (w < 0.0) norm = -norm;
    w = w / norm;
    x = x / norm;
    y = y / norm;
    z = z / norm;
    const double s = std::sqrt(x * x + y * y + z * z);
    const double theta = 2.0 * std::atan2(s, w);
    double scale;
    if (theta <= 1e-3) {  // theta / sin(theta / 2) by its series
        const double t2 = theta * theta;
        scale = 2.0 + t2 / 12.0 + 7.0 * t2 * t2 / 2880.0;
    } else {
        scale = theta / std::sin(0.5 * theta);
    }
    out[0] = scale * x;
    out[1] = scale * y;
    out[2] = scale * z;
}

}  // namespace plants
