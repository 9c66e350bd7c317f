// The plant's energy in plants._core (plants/core/cooperative_energy.h): the control terms at x, then the energy
// from them whatever their status, as the loop's kernel does; planar or spatial by the shape of the plant's bases.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>

#include <cstdint>
#include <vector>

#include "plants/core/binding_checks.h"
#include "plants/core/cooperative_energy.h"
#include "plants/core/planar_plant_reader.h"
#include "plants/core/spatial_plant_reader.h"

namespace plants::binding {

namespace {

nb::tuple energy_tuple(const PlantEnergy& e) { return nb::make_tuple(e.total, e.kinetic, e.status); }

nb::tuple plant_energy_py(Vector x, nb::handle P) {
    expect(x.shape(0) % 2 == 0, "x", "an even length 2 nz");
    const int nx = static_cast<int>(x.shape(0));
    int64_t status[2] = {0, 0};
    if (nb::cast<int>(P.attr("bases").attr("ndim")) == 3) {  // a spatial plant's bases (m, 4, 4)
        SpatialPlant plant(P);
        SpatialWork w(plant.model);
        spatial_control_terms(plant.model, x.data(), nx, status, w.data, w.terms);
        return energy_tuple(spatial_plant_energy(plant.model, x.data(), nx, w.data, w.terms,
                                                 EnergyScratch{w.energy_F.data(), w.energy_dY_zero.data()}));
    }
    PlanarPlant plant(P);
    PlanarWork w(plant.model);
    planar_control_terms(plant.model, x.data(), nx, status, w.data, w.terms);
    std::vector<double> F(w.N * 3), dY_zero(w.N * 3);
    return energy_tuple(planar_plant_energy(plant.model, x.data(), nx, w.data, w.terms,
                                            EnergyScratch{F.data(), dY_zero.data()}));
}

}  // namespace

void bind_cooperative_energy(nb::module_& m) {
    m.def("plant_energy", &plant_energy_py, nb::arg("x"), nb::arg("P"),
          "(E, T, status) of a cooperative plant (its PlantArgs P) at x: total and kinetic energy [J], status "
          "nonzero where the elastic potential is undefined (coincident nodes); coopctrl.loop.energy.plant_energy.");
}

}  // namespace plants::binding
