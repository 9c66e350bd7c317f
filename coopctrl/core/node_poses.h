// The node (end-effector) poses of a run's recorded states (coopctrl/results/node_poses.py calls it; the plant's own
// node poses per sample, bit for bit):
//     Y_nodes[k, i] = Phi_i(q_i(t_k))   [m, rad]
// for every sample k whose state row X[k] is finite; rows that are not finite are left as they are (the caller
// fills them with NaN). Spatial: the forward kinematics alone (plants/core/chain_arm.h's chain_arm_pose, the pose
// chain_arm_terms computes); planar: the node state (plants/core/cooperative_planar.h's planar_node_state).
#pragma once

#include <cstdint>

#include "plants/core/chain_arm.h"
#include "plants/core/cooperative_planar.h"
#include "plants/core/cooperative_spatial.h"

namespace coopctrl {

/// The recorded states and where their poses go.
struct NodePoseRecord {
    const double* X;  ///< (rows, width) states, row-major
    int rows;         ///< samples
    int width;        ///< state size nx = 2 nz
    double* out;      ///< (rows, m, p) node poses of the arms' nodes (node 0, the object, is not written)
};

/// Spatial plant: out[k] (m, 6) for each finite row X[k]. Y (N, 6) and chain (nmax + 1 rows) are work.
/// Returns the first row whose kinematics failed (status[0] = ELASTIC_EULER_SINGULAR, status[1] the node), or -1.
int64_t spatial_node_poses(const plants::SpatialCooperativeModel& model, const NodePoseRecord& record,
                           double* Y, plants::ChainBody* chain, int64_t* status) noexcept;

/// Planar plant: out[k] (m, 3) for each finite row X[k], from planar_node_state into data. Returns as
/// spatial_node_poses (the planar kinematics do not fail: -1).
int64_t planar_node_poses(const plants::PlanarCooperativeModel& model, const NodePoseRecord& record,
                          plants::PlanarCooperativeData& data, int64_t* status) noexcept;

}  // namespace coopctrl
