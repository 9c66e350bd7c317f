// A planar cooperative plant's model (PlanarCooperativeModel) read from its kernel arrays by name
// (plants.cooperative.plant_args.PlantArgs), and its workspace owned: what a binding builds once to call the
// planar kernels (plants/core/cooperative_planar.h). Shared by plants._core and coopctrl._core's tick.
#pragma once

#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "plants/core/binding_checks.h"
#include "plants/core/cooperative_planar.h"
#include "plants/core/cooperative_planar_work.h"

namespace plants::binding {

using plants::PlanarWork;

using Index = nb::ndarray<const std::int64_t, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
using IndexMatrix = nb::ndarray<const std::int64_t, nb::ndim<2>, nb::c_contig, nb::device::cpu>;

/// A planar plant's model read from its PlantArgs, with the storage its pointers point into.
struct PlanarPlant {
    std::vector<PlanarCooperativeArm> arms;
    std::vector<PlanarNode> nodes;
    PlanarCooperativeModel model{};
    // the arrays the model points into, kept alive
    nb::object P;

    explicit PlanarPlant(nb::handle args) : P(nb::borrow(args)) {
        auto kind = nb::cast<Index>(args.attr("arm_kind"));
        auto dof = nb::cast<Index>(args.attr("arm_dof"));
        auto q_off = nb::cast<Index>(args.attr("q_off"));
        auto tables = nb::cast<Matrix>(args.attr("tables"));
        auto table_off = nb::cast<Index>(args.attr("table_off"));
        auto bases = nb::cast<Matrix>(args.attr("bases"));
        auto tools = nb::cast<Matrix>(args.attr("tools"));
        auto gravity = nb::cast<Vector>(args.attr("gravity"));
        auto node_params = nb::cast<Matrix>(args.attr("node_params"));
        auto edge_index = nb::cast<IndexMatrix>(args.attr("edge_index"));
        auto edge_params = nb::cast<Matrix>(args.attr("edge_params"));
        auto Y_ref = nb::cast<Matrix>(args.attr("Y_ref"));
        const size_t m = kind.shape(0);
        expect(bases.shape(0) == m && bases.shape(1) == 3, "P.bases", "(m, 3): a planar plant's");
        expect(tools.shape(0) == m && tools.shape(1) == 3, "P.tools", "(m, 3)");
        expect(dof.shape(0) == m && q_off.shape(0) == m && table_off.shape(0) == m, "P.arm_dof, P.q_off, P.table_off",
               "m entries each");
        expect(tables.shape(1) == 7, "P.tables", "7 columns (planar links)");
        expect_length(gravity.shape(0), 2, "P.gravity");
        expect(node_params.shape(0) == m + 1 && node_params.shape(1) >= 2, "P.node_params", "(m + 1, >= 2)");
        expect(edge_index.shape(1) == 4, "P.edge_index", "(e, 4)");
        expect(edge_params.shape(0) == edge_index.shape(0) && edge_params.shape(1) == PLANAR_EDGE_WIDTH,
               "P.edge_params", "(e, " + std::to_string(PLANAR_EDGE_WIDTH) + ")");
        expect(Y_ref.shape(0) == m + 1 && Y_ref.shape(1) == 3, "P.Y_ref", "(m + 1, 3)");
        int nmax = 3;
        for (size_t i = 0; i < m; ++i) {
            PlanarCooperativeArm a{};
            a.kind = static_cast<ArmKind>(kind(i));
            a.dof = static_cast<int>(dof(i));
            a.q_offset = static_cast<int>(q_off(i));
            expect(a.kind == ARM_SERIAL || a.kind == ARM_CONTACT_POINT, "P.arm_kind", "0 (serial) or 1 (contact)");
            if (a.kind == ARM_SERIAL) {
                expect(table_off(i) >= 0 && static_cast<size_t>(table_off(i) + a.dof) <= tables.shape(0),
                       "P.table_off", "rows inside P.tables");
                a.arm.dof = a.dof;
                a.arm.links = reinterpret_cast<const PlanarLink*>(tables.data() + table_off(i) * 7);
                for (int c = 0; c < 3; ++c) {
                    a.arm.base[c] = bases(i, c);
                    a.arm.tool[c] = tools(i, c);
                }
                a.arm.gravity[0] = gravity(0);
                a.arm.gravity[1] = gravity(1);
            }
            nmax = std::max(nmax, a.dof);
            arms.push_back(a);
        }
        for (size_t k = 0; k <= m; ++k) nodes.push_back(PlanarNode{node_params(k, 0), node_params(k, 1)});
        model.arm_count = static_cast<int>(m);
        model.arms = arms.data();
        model.nodes = nodes.data();
        model.interconnections = Interconnections{static_cast<int>(edge_index.shape(0)),
                                                  reinterpret_cast<const ElasticEdge*>(edge_index.data()),
                                                  edge_params.data(), PLANAR_EDGE_WIDTH};
        model.gravity[0] = gravity(0);
        model.gravity[1] = gravity(1);
        model.Y_ref = Y_ref.data();
        model.immobile = nb::cast<bool>(args.attr("immobile"));
        model.nmax = nmax;
    }
};


}  // namespace plants::binding
