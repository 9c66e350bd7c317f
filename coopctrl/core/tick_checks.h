// Two small stages of a tick: the object's required wrench and
// the guards on the state.
#pragma once

namespace coopctrl {

/// Codes of the guards (the tick's stop codes of the same numbers, tick_model.h's TickCode).
enum GuardCode : int {
    GUARD_OK = 0,                ///< DONE: every guard passed
    GUARD_NONFINITE = 1,         ///< NONFINITE: the state is not finite
    GUARD_NEAR_SINGULARITY = 2,  ///< NEAR_SINGULARITY: a node entered the Euler-angle band
    GUARD_DEFORMATION = 3,       ///< DEFORMATION: a contact deformed beyond max_deformation
};

/// The object's required wrench w_N [N, N m] to follow (Y0, dY0, ddY0) (coopctrl.controllers.required_object_wrench):
/// spatial: force m (ddr - g), moment R(A) (I dw + w x I w) with the body rates (w, dw) of (A, dA, ddA) and the
/// principal inertia (3,) [kg m^2]; planar: (m (ddx - gx), m (ddz - gz), I ddtheta).
void required_wrench(bool spatial, double mass, const double* inertia, const double* gravity, const double* Y0,
                     const double* dY0, const double* ddY0, double* out) noexcept;

/// The guards on the state x (nx) with the node poses Y ((m + 1) x p, row 0 the object): a non-finite state; (spatial)
/// a node with |cos theta| < band; a contact whose offset from the object, in the object frame, is farther than
/// max_deformation [m] from its grasp point rho (m x npos). Returns a GuardCode; at GUARD_DEFORMATION the contact
/// and its deformation [m] in *contact, *deformation.
int guards(bool spatial, const double* x, int nx, const double* Y, int m, const double* rho, double band,
           double max_deformation, int* contact, double* deformation) noexcept;

}  // namespace coopctrl
