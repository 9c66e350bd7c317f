// A spatial cooperative plant's model (SpatialCooperativeModel) read from its kernel arrays by name
// (plants.cooperative.plant_args.PlantArgs), and its workspace owned: what a binding builds once to call the
// spatial kernels (plants/core/cooperative_spatial.h). Header-only, for plants._core and coopctrl._core's tick.
#pragma once

#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "plants/core/binding_checks.h"
#include "plants/core/chain_arm.h"
#include "plants/core/cooperative_spatial.h"
#include "plants/core/cooperative_spatial_work.h"
#include "plants/core/elastic_model.h"

namespace plants::binding {

using plants::SpatialWork;

using Index = nb::ndarray<const std::int64_t, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
using IndexMatrix = nb::ndarray<const std::int64_t, nb::ndim<2>, nb::c_contig, nb::device::cpu>;
using Tensor3 = nb::ndarray<const double, nb::ndim<3>, nb::c_contig, nb::device::cpu>;

/// A spatial plant's model read from its PlantArgs, with the storage its pointers point into. The bases, tools
/// and gravity are copied into the arms' models: a plant whose world moves (CooperativePlant.with_own_world)
/// is read again.
struct SpatialPlant {
    std::vector<SpatialCooperativeArm> arms;
    SpatialCooperativeModel model{};
    // the arrays the model points into, kept alive
    nb::object P;

    explicit SpatialPlant(nb::handle args) : P(nb::borrow(args)) {
        constexpr size_t table_width = sizeof(ChainJointRow) / sizeof(double);
        auto kind = nb::cast<Index>(args.attr("arm_kind"));
        auto dof = nb::cast<Index>(args.attr("arm_dof"));
        auto q_off = nb::cast<Index>(args.attr("q_off"));
        auto tables = nb::cast<Matrix>(args.attr("tables"));
        auto table_off = nb::cast<Index>(args.attr("table_off"));
        expect(nb::cast<int>(args.attr("bases").attr("ndim")) == 3, "P.bases", "(m, 4, 4): a spatial plant's");
        auto bases = nb::cast<Tensor3>(args.attr("bases"));
        auto tools = nb::cast<Tensor3>(args.attr("tools"));
        auto gravity = nb::cast<Vector>(args.attr("gravity"));
        auto node_params = nb::cast<Matrix>(args.attr("node_params"));
        auto edge_index = nb::cast<IndexMatrix>(args.attr("edge_index"));
        auto edge_params = nb::cast<Matrix>(args.attr("edge_params"));
        auto Y_ref = nb::cast<Matrix>(args.attr("Y_ref"));
        const size_t m = kind.shape(0);
        expect(bases.shape(0) == m && bases.shape(1) == 4 && bases.shape(2) == 4, "P.bases", "(m, 4, 4)");
        expect(tools.shape(0) == m && tools.shape(1) == 4 && tools.shape(2) == 4, "P.tools", "(m, 4, 4)");
        expect(dof.shape(0) == m && q_off.shape(0) == m && table_off.shape(0) == m, "P.arm_dof, P.q_off, P.table_off",
               "m entries each");
        expect(tables.shape(1) == table_width, "P.tables", "32 columns (chain joint rows)");
        expect_length(gravity.shape(0), 3, "P.gravity");
        expect(node_params.shape(0) == m + 1 &&
                   (node_params.shape(1) == SPATIAL_NODE_WIDTH || node_params.shape(1) == SPATIAL_NODE_WIDTH_CHARTED),
               "P.node_params", "(m + 1, 4) or (m + 1, 14) (with charts)");
        expect(edge_index.shape(1) == 4, "P.edge_index", "(e, 4)");
        expect(edge_params.shape(0) == edge_index.shape(0) && edge_params.shape(1) == SPATIAL_EDGE_WIDTH,
               "P.edge_params", "(e, " + std::to_string(SPATIAL_EDGE_WIDTH) + ")");
        expect(Y_ref.shape(0) == m + 1 && Y_ref.shape(1) == 6, "P.Y_ref", "(m + 1, 6)");
        int nmax = 6;
        for (size_t i = 0; i < m; ++i) {
            SpatialCooperativeArm a{};
            a.kind = static_cast<ArmKind>(kind(i));
            a.dof = static_cast<int>(dof(i));
            a.q_offset = static_cast<int>(q_off(i));
            expect(a.kind == ARM_SERIAL || a.kind == ARM_CONTACT_POINT || a.kind == ARM_SERIAL_OWN_CHART,
                   "P.arm_kind", "0 (serial), 1 (contact) or 2 (serial, own chart)");
            if (a.kind != ARM_CONTACT_POINT) {
                expect(table_off(i) >= 0 && static_cast<size_t>(table_off(i) + a.dof) <= tables.shape(0),
                       "P.table_off", "rows inside P.tables");
                a.arm.dof = a.dof;
                a.arm.joints = reinterpret_cast<const ChainJointRow*>(tables.data() + table_off(i) * table_width);
                for (size_t r = 0; r < 4; ++r)
                    for (size_t c = 0; c < 4; ++c) {
                        a.arm.base[4 * r + c] = bases(i, r, c);
                        a.arm.tool[4 * r + c] = tools(i, r, c);
                    }
                for (size_t c = 0; c < 3; ++c) a.arm.gravity[c] = gravity(c);
            } else {
                expect(a.dof == 6, "P.arm_dof", "6 for a spatial contact point");
            }
            nmax = std::max(nmax, a.dof);
            arms.push_back(a);
        }
        model.arm_count = static_cast<int>(m);
        model.arms = arms.data();
        model.node_rows = node_params.data();
        model.node_width = static_cast<int>(node_params.shape(1));
        model.interconnections = Interconnections{static_cast<int>(edge_index.shape(0)),
                                                  reinterpret_cast<const ElasticEdge*>(edge_index.data()),
                                                  edge_params.data(), SPATIAL_EDGE_WIDTH};
        for (size_t c = 0; c < 3; ++c) model.gravity[c] = gravity(c);
        model.Y_ref = Y_ref.data();
        model.immobile = nb::cast<bool>(args.attr("immobile"));
        model.nmax = nmax;
    }
    /// Read the bases and gravity again from P (a world chart turned them in place: coopctrl.loop.charts).
    void read_world() {
        auto bases = nb::cast<Tensor3>(P.attr("bases"));
        auto gravity = nb::cast<Vector>(P.attr("gravity"));
        expect(bases.shape(0) == arms.size() && bases.shape(1) == 4 && bases.shape(2) == 4, "P.bases", "(m, 4, 4)");
        expect_length(gravity.shape(0), 3, "P.gravity");
        for (size_t i = 0; i < arms.size(); ++i) {
            if (arms[i].kind == ARM_CONTACT_POINT) continue;
            for (size_t r = 0; r < 4; ++r)
                for (size_t c = 0; c < 4; ++c) arms[i].arm.base[4 * r + c] = bases(i, r, c);
            for (size_t c = 0; c < 3; ++c) arms[i].arm.gravity[c] = gravity(c);
        }
        for (size_t c = 0; c < 3; ++c) model.gravity[c] = gravity(c);
    }
    // the model points into this object's vectors: a move keeps their storage, a copy would not
    SpatialPlant(SpatialPlant&&) = default;
    SpatialPlant(const SpatialPlant&) = delete;
    SpatialPlant& operator=(const SpatialPlant&) = delete;
};


}  // namespace plants::binding
