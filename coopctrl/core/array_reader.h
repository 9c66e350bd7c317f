// Arrays read from a Python object's attributes by name, without copies, each checked once (dtype, C order,
// shape) with a one-line error naming the attribute: what the bindings use to build a run's model and data.
#pragma once

#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>

#include <cstdint>
#include <initializer_list>
#include <string>

namespace coopctrl::binding {

namespace nb = nanobind;

/// Any extent of a dimension.
constexpr int64_t ANY = -1;

inline std::string shape_text(std::initializer_list<int64_t> shape) {
    std::string s = "(";
    bool first = true;
    for (int64_t d : shape) {
        s += (first ? "" : ", ") + (d == ANY ? std::string("*") : std::to_string(d));
        first = false;
    }
    return s + (shape.size() == 1 ? ",)" : ")");
}

/// The data of owner.name, a C-contiguous array of T with this shape (ANY: any extent); `what` names the owner.
template <class T>
T* array_field(nb::handle owner, const char* what, const char* name, std::initializer_list<int64_t> shape) {
    nb::ndarray<T, nb::c_contig, nb::device::cpu> a;
    const std::string where = std::string(what) + "." + name;
    const char* dtype = sizeof(T) == 8 && static_cast<T>(0.5) != 0 ? "float64" : "int64";
    if (!nb::try_cast(owner.attr(name), a, false))
        throw nb::value_error((where + ": expected a C-contiguous " + dtype + " array").c_str());
    bool ok = a.ndim() == shape.size();
    size_t d = 0;
    for (int64_t want : shape) {
        if (ok && want != ANY && static_cast<int64_t>(a.shape(d)) != want) ok = false;
        ++d;
    }
    if (!ok) {
        std::string got = "(";
        for (size_t c = 0; c < a.ndim(); ++c) got += (c ? ", " : "") + std::to_string(a.shape(c));
        throw nb::value_error((where + ": expected shape " + shape_text(shape) + ", got " + got + ")").c_str());
    }
    return a.data();
}

inline double* doubles(nb::handle owner, const char* what, const char* name, std::initializer_list<int64_t> shape) {
    return array_field<double>(owner, what, name, shape);
}

inline int64_t* ints(nb::handle owner, const char* what, const char* name, std::initializer_list<int64_t> shape) {
    return array_field<int64_t>(owner, what, name, shape);
}

/// The extent of dimension `dim` of owner.name (an array of any dtype).
inline int64_t extent(nb::handle owner, const char* name, size_t dim) {
    nb::ndarray<nb::device::cpu> a = nb::cast<nb::ndarray<nb::device::cpu>>(owner.attr(name));
    if (dim >= a.ndim()) throw nb::value_error((std::string(name) + ": expected at least " +
                                                std::to_string(dim + 1) + " dimensions").c_str());
    return static_cast<int64_t>(a.shape(dim));
}

}  // namespace coopctrl::binding
