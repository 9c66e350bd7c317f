// A planar cooperative plant's workspace (PlanarCooperativeData) and control terms, owned: made once per run by
// whoever calls the planar kernels (a binding, the tick's plant).
#pragma once

#include <vector>

#include "plants/core/cooperative_planar.h"

namespace plants {

/// A planar plant's workspace (PlanarCooperativeData) and control terms, owned.
struct PlanarWork {
    int N, m, nmax;
    std::vector<double> Y, dY, H, h, J, Jdq, w, Nm, rhs, qdd, chain, W, w_free, S, Fw, Fe;
    PlanarCooperativeData data{};
    PlanarControlTerms terms{};
    explicit PlanarWork(const PlanarCooperativeModel& model)
        : N(model.arm_count + 1), m(model.arm_count), nmax(model.nmax), Y(N * 3), dY(N * 3), H(m * nmax * nmax),
          h(m * nmax), J(m * 3 * nmax), Jdq(m * 3), w(N * 3), Nm(nmax * nmax), rhs(nmax), qdd(nmax),
          chain((nmax + 1) * PLANAR_WORK_WIDTH), W(N * 9), w_free(N * 3), S(N * 3), Fw(m * 3), Fe(N * 3) {
        data = PlanarCooperativeData{Y.data(), dY.data(), H.data(), h.data(), J.data(), Jdq.data(), w.data(),
                                     Nm.data(), rhs.data(), qdd.data(), chain.data()};
        terms = PlanarControlTerms{W.data(), w_free.data(), S.data(), Fw.data(), Fe.data()};
    }
    // data and terms point into this object's vectors: a move keeps their storage, a copy would not
    PlanarWork(PlanarWork&&) = default;
    PlanarWork(const PlanarWork&) = delete;
    PlanarWork& operator=(const PlanarWork&) = delete;
};

}  // namespace plants
