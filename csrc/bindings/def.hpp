// One line binds a kernel: def(m, "name", &kernel, "a"_a, "b"_a, doc). Each argument is
// taken as the kernel's parameter type says: a View<T, D> from a numpy array checked by
// view_of under its nb::arg name, a struct of arrays by read_struct, a cplx from any Python
// number, a bool from Python's or numpy's, anything else as nanobind casts it. Then no
// array the kernel writes may share memory with another of its arrays, and the kernel (or
// the library's checked entry point) checks the rest.
#pragma once

#include <nanobind/nanobind.h>
#include <nanobind/stl/pair.h>

#include <array>
#include <cstring>
#include <stdexcept>
#include <string>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include <bearing_core/core/complex.hpp>
#include "bindings/arrays.hpp"
#include "bindings/structs.hpp"

namespace bearing::bindings {
// A bool argument: Python's or numpy's (numba takes both).
struct Bool {
    bool value = false;
};
}  // namespace bearing::bindings

namespace nanobind::detail {

// Python's complex (or any number it takes) as the library's cplx, and back.
template <>
struct type_caster<bearing::cplx> {
    NB_TYPE_CASTER(bearing::cplx, const_name("complex"))
    bool from_python(handle src, uint32_t, cleanup_list*) noexcept {
        const Py_complex z = PyComplex_AsCComplex(src.ptr());
        if (z.real == -1.0 && PyErr_Occurred()) {
            PyErr_Clear();
            return false;
        }
        value = {z.real, z.imag};
        return true;
    }
    static handle from_cpp(bearing::cplx z, rv_policy, cleanup_list*) noexcept {
        return PyComplex_FromDoubles(z.re, z.im);
    }
};

template <>
struct type_caster<bearing::bindings::Bool> {
    NB_TYPE_CASTER(bearing::bindings::Bool, const_name("bool"))
    bool from_python(handle src, uint32_t, cleanup_list*) noexcept {
        const char* type = Py_TYPE(src.ptr())->tp_name;
        if (!PyBool_Check(src.ptr()) && std::strcmp(type, "numpy.bool") != 0 &&
            std::strcmp(type, "numpy.bool_") != 0) {
            return false;
        }
        value.value = PyObject_IsTrue(src.ptr()) == 1;
        return true;
    }
};

}  // namespace nanobind::detail

namespace bearing::bindings {

// How a kernel's parameter of type P comes from Python: nanobind casts a Py, and
// from(py, name) makes the P.
template <class P, class = void>
struct Param {
    using Py = P;
    static P from(P value, const char*) { return value; }
};
template <>
struct Param<bool> {
    using Py = Bool;
    static bool from(Bool value, const char*) { return value.value; }
};
// A struct of arrays (its schema's for_each_field and field_docs): read_struct's views.
template <class S>
struct Param<S, std::void_t<decltype(field_docs(std::declval<const S&>()))>> {
    using Py = nb::handle;
    static S from(nb::handle obj, const char* name) {
        schema::Sizes sizes{{"CAPACITY", slam::CAPACITY}};
        Kept kept;  // (the caller's arguments stay alive through the call)
        return read_struct<S>(obj, name, sizes, kept, false);
    }
};
template <class T, int D>
struct Param<View<T, D>> {
    using Py = nb::handle;
    static View<T, D> from(nb::handle obj, const char* name) { return view_of<T, D>(obj, name); }
};

// The names of the nb::arg among a def's extras, in order.
template <class Extra>
void add_name(std::vector<const char*>& names, const Extra& extra) {
    if constexpr (std::is_base_of_v<nb::arg, Extra> || std::is_base_of_v<nb::arg_v, Extra>) {
        names.push_back(extra.name_);
    }
}

// The array arguments' memory, for require_apart.
template <class P>
void add_extent(std::vector<Extent>&, const P&, const char*) {}
template <class T, int D>
void add_extent(std::vector<Extent>& extents, const View<T, D>& view, const char* name) {
    extents.push_back(extent_of(view, name));
}

template <bool Release, class R, class... P, size_t... I, class... Extra>
void def_kernel(nb::module_& m, const char* name, R (*kernel)(P...), std::index_sequence<I...>,
                const Extra&... extra) {
    std::vector<const char*> given;
    (add_name(given, extra), ...);
    if (given.size() != sizeof...(P)) throw std::logic_error(std::string(name) + ": arg names");
    const std::array<const char*, sizeof...(P)> names{given[I]...};
    m.def(
        name,
        [kernel, names](typename Param<P>::Py... py) -> R {
            std::tuple<P...> args{Param<P>::from(std::forward<decltype(py)>(py), names[I])...};
            std::vector<Extent> extents;
            (add_extent(extents, std::get<I>(args), names[I]), ...);
            require_apart(extents);
            if constexpr (Release) {
                nb::gil_scoped_release release;
                return std::apply(kernel, args);
            } else {
                return std::apply(kernel, args);
            }
        },
        extra...);
}

// Binds `kernel` (a function, or a lambda's + pointer) as `name`, its arguments named by
// the nb::arg among `extra`.
template <class R, class... P, class... Extra>
void def(nb::module_& m, const char* name, R (*kernel)(P...), const Extra&... extra) {
    def_kernel<false>(m, name, kernel, std::index_sequence_for<P...>{}, extra...);
}
// def, the GIL released while the kernel runs (after every argument is taken).
template <class R, class... P, class... Extra>
void def_released(nb::module_& m, const char* name, R (*kernel)(P...), const Extra&... extra) {
    def_kernel<true>(m, name, kernel, std::index_sequence_for<P...>{}, extra...);
}

}  // namespace bearing::bindings

// The IntEnum Type of the module `m`, its members (also at module level) from the enum's
// X-macro LIST (E(member, value) per member).
#define BEARING_BINDINGS_ENUM_VALUE(member, number) .value(#member, Enum::member)
#define BEARING_BINDINGS_ENUM(m, Type, LIST)                                             \
    {                                                                                    \
        using Enum = Type;                                                               \
        nb::enum_<Enum>(m, #Type, nb::is_arithmetic()) LIST(BEARING_BINDINGS_ENUM_VALUE) \
            .export_values();                                                            \
    }
