// A spatial cooperative plant's workspace (SpatialCooperativeData), control terms and energy scratch, owned: made
// once per run by whoever calls the spatial kernels (a binding, the tick's plant).
#pragma once

#include <vector>

#include "plants/core/cooperative_spatial.h"

namespace plants {

/// A spatial plant's workspace (SpatialCooperativeData), control terms and energy scratch, owned, zero-filled.
struct SpatialWork {
    int N, m, nmax;
    std::vector<double> Y, dY, H, h, J, Jdq, Wr, w, Nm, rhs, qdd, WJ, arm_H, arm_J, W, w_free, S, Fw, Fe;
    std::vector<ChainBody> chain;
    std::vector<NodeFrames> frames;
    std::vector<double> energy_F, energy_dY_zero;  ///< (N, 6) each: cooperative_energy.h's EnergyScratch
    SpatialCooperativeData data{};
    SpatialControlTerms terms{};
    explicit SpatialWork(const SpatialCooperativeModel& model)
        : N(model.arm_count + 1), m(model.arm_count), nmax(model.nmax), Y(N * 6), dY(N * 6), H(m * nmax * nmax),
          h(m * nmax), J(m * 6 * nmax), Jdq(m * 6), Wr(N * 9), w(N * 6), Nm(nmax * nmax), rhs(nmax), qdd(nmax),
          WJ(3 * nmax), arm_H(nmax * nmax), arm_J(6 * nmax), W(N * 36), w_free(N * 6), S(N * 6), Fw(m * 6),
          Fe(N * 6), chain(nmax + 1), frames(N), energy_F(N * 6), energy_dY_zero(N * 6) {
        data = SpatialCooperativeData{Y.data(),  dY.data(),  H.data(),     h.data(),     J.data(),     Jdq.data(),
                                      Wr.data(), w.data(),   Nm.data(),    rhs.data(),   qdd.data(),   WJ.data(),
                                      arm_H.data(), arm_J.data(), chain.data(), frames.data()};
        terms = SpatialControlTerms{W.data(), w_free.data(), S.data(), Fw.data(), Fe.data()};
    }
    // data and terms point into this object's vectors: a move keeps their storage, a copy would not
    SpatialWork(SpatialWork&&) = default;
    SpatialWork(const SpatialWork&) = delete;
    SpatialWork& operator=(const SpatialWork&) = delete;
};

}  // namespace plants
