// What a run carries from tick to tick and how it stopped, as classes of coopctrl._core with named fields (as
// MuJoCo's mjData): LoopFlags and HoldState (coopctrl.loop.state.LoopState.flags, .hold) and StopReport
// (coopctrl.loop.data.LoopData.stop). The tick writes them in place (tick_model.h); Python reads and sets them by
// name. Each copies, deep-copies, pickles (its bytes), compares field by field and prints its fields.
#include <nanobind/nanobind.h>
#include <nanobind/stl/array.h>
#include <nanobind/stl/string.h>

#include <array>
#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

#include "coopctrl/core/run_state.h"

namespace nb = nanobind;

namespace coopctrl::binding {

namespace {

/// Copy, deep copy, pickling, equality and repr of a plain struct T whose fields `names` the repr shows.
template <class T>
void value_semantics(nb::class_<T>& cls, const char* type_name, std::initializer_list<const char*> names) {
    static_assert(std::is_trivially_copyable_v<T>, "a run-state struct is plain data");
    std::vector<std::string> fields(names.begin(), names.end());
    cls.def(nb::init<>())
        .def("__copy__", [](const T& s) { return T(s); })
        .def("__deepcopy__", [](const T& s, nb::handle) { return T(s); }, nb::arg("memo"))
        .def("copy", [](const T& s) { return T(s); }, "A copy that shares nothing with this one.")
        .def("assign", [](T& s, const T& other) { s = other; }, nb::arg("other"), "Set every field from other.")
        .def("__getstate__", [](const T& s) { return nb::bytes(reinterpret_cast<const char*>(&s), sizeof(T)); })
        .def("__setstate__",
             [](T& s, nb::bytes b) {
                 if (b.size() != sizeof(T)) throw nb::value_error("a pickled run-state struct of another size");
                 new (&s) T();
                 std::memcpy(&s, b.c_str(), sizeof(T));
             })
        .def("__eq__", [](const T& a, const T& b) { return std::memcmp(&a, &b, sizeof(T)) == 0; })
        .def("__repr__", [type_name, fields](nb::handle self) {
            std::string out = std::string(type_name) + "(";
            for (size_t i = 0; i < fields.size(); ++i) {
                out += (i ? ", " : "") + fields[i] + "=" + nb::cast<std::string>(nb::repr(self.attr(fields[i].c_str())));
            }
            return out + ")";
        });
}

}  // namespace

void bind_loop_state(nb::module_& m) {
    nb::class_<LoopFlags> flags(m, "LoopFlags",
                                "A run's tallies, carried from tick to tick (coopctrl.loop.state.LoopState.flags).");
    flags.def_rw("have_last_split", &LoopFlags::have_last_split, "1 once a feasible split has been solved.")
        .def_rw("consecutive_failures", &LoopFlags::consecutive_failures, "Failed QP solves in a row.")
        .def_rw("saturated_ticks", &LoopFlags::saturated_ticks, "Ticks with a saturated joint.")
        .def_rw("qp_solves", &LoopFlags::qp_solves, "QP solves so far (the first starts cold).")
        .def_rw("first_saturated", &LoopFlags::first_saturated, "The first saturated tick (-1: none).")
        .def_rw("last_saturated", &LoopFlags::last_saturated, "The last saturated tick (-1: none).")
        .def_rw("advance_first", &LoopFlags::advance_first,
                "1: the plant is yet to advance over the last recorded tick's period (a continuation does it first).");
    value_semantics(flags, "LoopFlags",
                    {"have_last_split", "consecutive_failures", "saturated_ticks", "qp_solves", "first_saturated",
                     "last_saturated", "advance_first"});

    nb::class_<HoldState> hold(m, "HoldState",
                               "The next tick's hold of the last feasible split (coopctrl.loop.state.LoopState.hold).");
    hold.def_rw("mode", &HoldState::mode, "1: the next tick takes the last feasible split.")
        .def_rw("qp_status", &HoldState::qp_status, "The failed solve's status code, recorded.")
        .def_rw("iterations", &HoldState::iterations, "Its iterations, recorded.")
        .def_rw("binding", &HoldState::binding, "Its binding families (a mask).");
    value_semantics(hold, "HoldState", {"mode", "qp_status", "iterations", "binding"});

    nb::class_<StopReport> stop(m, "StopReport",
                                "How a run of the tick stopped (coopctrl.loop.data.LoopData.stop): its code "
                                "(coopctrl.loop.tick_codes), where, and the code's details.");
    stop.def_rw("code", &StopReport::code, "The stop code (coopctrl.loop.tick_codes).")
        .def_rw("tick", &StopReport::tick, "The tick it stopped at, or where to resume.")
        .def_prop_rw(
            "detail", [](const StopReport& s) { return std::array<int64_t, 3>{s.detail[0], s.detail[1], s.detail[2]}; },
            [](StopReport& s, std::array<int64_t, 3> v) { std::memcpy(s.detail, v.data(), sizeof(s.detail)); },
            "The code's three integer details (coopctrl.loop.tick_codes says which).")
        .def_rw("ticks_recorded", &StopReport::ticks_recorded, "Rows of the record written.")
        .def_rw("last_good_tick", &StopReport::last_good_tick,
                "The last tick whose state passed the guards (-1: none).")
        .def_rw("rhs_evaluations", &StopReport::rhs_evaluations, "Right-hand-side evaluations so far.")
        .def_prop_rw(
            "value", [](const StopReport& s) { return std::array<double, 2>{s.value[0], s.value[1]}; },
            [](StopReport& s, std::array<double, 2> v) { std::memcpy(s.value, v.data(), sizeof(s.value)); },
            "The code's two real details (coopctrl.loop.tick_codes says which).");
    value_semantics(stop, "StopReport",
                    {"code", "tick", "detail", "ticks_recorded", "last_good_tick", "rhs_evaluations", "value"});
}

}  // namespace coopctrl::binding
