#include "coopctrl/core/node_poses.h"

#include <cmath>

#include "plants/core/elastic_model.h"

namespace coopctrl {

namespace {

bool finite_row(const double* x, int width) noexcept {
    for (int j = 0; j < width; ++j)
        if (!std::isfinite(x[j])) return false;
    return true;
}

}  // namespace

int64_t spatial_node_poses(const plants::SpatialCooperativeModel& model, const NodePoseRecord& record,
                           double* Y, plants::ChainBody* chain, int64_t* status) noexcept {
    const int m = model.arm_count, nz = record.width / 2;
    for (int k = 0; k < record.rows; ++k) {
        const double* x = record.X + static_cast<long>(k) * record.width;
        if (!finite_row(x, record.width)) continue;
        // node_poses_into of plants/cooperative/_spatial_kernel.py
        status[0] = plants::ELASTIC_OK;
        for (int a = 0; a < 6; ++a) Y[a] = x[nz - 6 + a];
        for (int i = 0; i < m; ++i) {
            const plants::SpatialCooperativeArm& arm = model.arms[i];
            double* Yi = Y + (i + 1) * 6;
            if (arm.kind != plants::ARM_CONTACT_POINT) {
                if (plants::chain_arm_pose(arm.arm, x + arm.q_offset, arm.kind == plants::ARM_SERIAL_OWN_CHART,
                                           chain, Yi) != 0) {
                    status[0] = plants::ELASTIC_EULER_SINGULAR;
                    status[1] = i + 1;
                    return k;
                }
            } else {
                for (int a = 0; a < 6; ++a) Yi[a] = x[arm.q_offset + a];
            }
        }
        double* out = record.out + static_cast<long>(k) * m * 6;
        for (int i = 0; i < m; ++i)
            for (int a = 0; a < 6; ++a) out[i * 6 + a] = Y[(i + 1) * 6 + a];
    }
    return -1;
}

int64_t planar_node_poses(const plants::PlanarCooperativeModel& model, const NodePoseRecord& record,
                          plants::PlanarCooperativeData& data, int64_t* status) noexcept {
    const int m = model.arm_count;
    for (int k = 0; k < record.rows; ++k) {
        const double* x = record.X + static_cast<long>(k) * record.width;
        if (!finite_row(x, record.width)) continue;
        plants::planar_node_state(model, x, record.width, status, data);
        if (status[0] != 0) return k;
        double* out = record.out + static_cast<long>(k) * m * 3;
        for (int i = 0; i < m; ++i)
            for (int a = 0; a < 3; ++a) out[i * 3 + a] = data.Y[(i + 1) * 3 + a];
    }
    return -1;
}

}  // namespace coopctrl
