// One line binds a kernel: def(m, "name", &kernel, "a"_a, "b"_a, doc). Each parameter is
// made from its Python argument (or arguments) as its type says (Param): a View<T, D> from
// a numpy array checked by view_of under its nb::arg name, a struct of arrays by
// read_struct, a map state from a MapState, a cplx from any Python number, a bool from
// Python's or numpy's, anything else as nanobind casts it. Then no array the kernel writes
// may share memory with another of its arrays, and the kernel (or the library's checked
// entry point) checks the rest. The library's structs the kernels take are parsed here too:
// a map batch's state, a group's Settings and the map update's Params.
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
#include <bearing_core/env/checked.hpp>
#include <bearing_core/slam/checked.hpp>
#include <bearing_core/slam/state.hpp>
#include "bindings/arrays.hpp"

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

// The lengths a map state's rules start from: its vertex capacity.
inline schema::Sizes map_sizes() { return {{"CAPACITY", slam::CAPACITY}}; }

// A map batch's state (`label` in messages): a MapState binding's (its State tuple,
// .state), a State tuple, or any object with State's arrays as attributes. Its 34 arrays
// are checked as the native update needs them: each against its shape rule (state.hpp)
// with `sizes`, which then holds the state's axes (maps, m, w, levels, h), the state
// against the update's buffers (checked::check_state), and the bool bytes it reads.
inline slam::MapState map_state_of(nb::handle obj, schema::Sizes& sizes, Kept& kept,
                                   const char* label = "maps") {
    nb::object source = nb::borrow(obj);
    if (!nb::isinstance<nb::tuple>(source) && !nb::hasattr(source, "vertices") &&
        nb::hasattr(source, "state")) {
        source = source.attr("state");
    }
    kept.push_back(source);
    const slam::MapState s = read_struct<slam::MapState>(source, label, sizes, kept, true);
    slam::checked::check_state(s, label);
    return s;
}

// A batch's state as the native update takes it: checked views of the arrays of a State,
// and the State (its arrays stay alive).
struct PyMapState {
    nb::object state;
    slam::MapState views;
    schema::Sizes sizes = map_sizes();  // then its axes: maps, m (mapped landmarks), w, levels, h

    explicit PyMapState(nb::handle source) : state(nb::borrow(source)) {
        Kept kept;  // (the State keeps its arrays alive)
        views = map_state_of(source, sizes, kept, "state");
    }
};

// A group's settings from a Settings (any object with its fields).
inline env::Settings settings_of(nb::handle obj, Kept& kept) {
    env::Settings s;
#define BEARING_BINDINGS_READ_SETTING(T, name, value, doc) \
    s.name = scalar_of<T>(obj, #name, "settings");
    BEARING_CORE_SETTINGS(BEARING_BINDINGS_READ_SETTING)
#undef BEARING_BINDINGS_READ_SETTING
    schema::Sizes sizes;
    const env::Settings arrays = read_struct<env::Settings>(obj, "", sizes, kept, false);
    s.obstacle_vertices = arrays.obstacle_vertices;
    s.obstacle_starts = arrays.obstacle_starts;
    env::checked::validate(s);
    return s;
}

// The map update's settings: the native Params, or any object with its fields.
inline slam::Params params_of(nb::handle obj) {
    slam::Params p;
    if (nb::try_cast(obj, p)) return p;
#define BEARING_BINDINGS_READ_SETTING(T, name, value, doc) \
    p.name = scalar_of<T>(obj, #name, "params");
    BEARING_CORE_PARAMS(BEARING_BINDINGS_READ_SETTING)
#undef BEARING_BINDINGS_READ_SETTING
    slam::validate(p);  // the native Params' ranges (the update's buffers are sized by them)
    return p;
}

// A call's parameters as they are made: the Python arguments' names, and the arrays'
// memory (for require_apart).
struct Taken {
    const char* const* names;
    std::vector<Extent> extents;
};

// How a kernel's parameter of type T comes from Python: Args, the Python arguments it takes
// (nanobind casts each; one, unless it says otherwise), and from(taken, at, args...), the
// T made of them (their names from taken.names[at]).
template <class T, class = void>
struct Param {
    using Arg = std::conditional_t<std::is_class_v<T>, const T&, T>;  // (T& stays T&)
    using Args = std::tuple<Arg>;
    static Arg from(Taken&, size_t, Arg value) { return value; }
};
template <>
struct Param<bool> {
    using Args = std::tuple<Bool>;
    static bool from(Taken&, size_t, Bool value) { return value.value; }
};
template <class T, int D>
struct Param<View<T, D>> {
    using Args = std::tuple<nb::handle>;
    static View<T, D> from(Taken& taken, size_t at, nb::handle obj) {
        const View<T, D> view = view_of<T, D>(obj, taken.names[at]);
        taken.extents.push_back(extent_of(view, taken.names[at]));
        return view;
    }
};
// A struct of arrays (its schema's for_each_field and field_docs): read_struct's views.
template <class S>
struct Param<S, std::void_t<decltype(field_docs(std::declval<const S&>()))>> {
    using Args = std::tuple<nb::handle>;
    static S from(Taken& taken, size_t at, nb::handle obj) {
        schema::Sizes sizes = map_sizes();
        Kept kept;  // (the caller's arguments stay alive through the call)
        return read_struct<S>(obj, taken.names[at], sizes, kept, false);
    }
};
// A map batch's state: a MapState's checked views.
template <>
struct Param<slam::MapState> {
    using Args = std::tuple<const PyMapState&>;
    static const slam::MapState& from(Taken&, size_t, const PyMapState& s) { return s.views; }
};
// A struct S of fields F..., each from its own Python argument, in order.
template <class S, class... F>
struct Fields {
    using Args = decltype(std::tuple_cat(std::declval<typename Param<F>::Args>()...));
    template <class... A>
    static S from(Taken& taken, size_t at, A&&... args) {
        size_t k = at;
        return S{Param<F>::from(taken, k++, std::forward<A>(args))...};
    }
};

// The Param of a kernel's parameter type P (a const P& or a P is made as a P).
template <class P>
using ParamOf = Param<std::conditional_t<std::is_const_v<std::remove_reference_t<P>>,
                                         std::remove_cv_t<std::remove_reference_t<P>>, P>>;
template <class P>
constexpr size_t arity = std::tuple_size_v<typename ParamOf<P>::Args>;
// Where each parameter's Python arguments start among all of a kernel's.
template <class... P>
constexpr std::array<size_t, sizeof...(P) + 1> starts() {
    const size_t arities[] = {0, arity<P>...};
    std::array<size_t, sizeof...(P) + 1> out{};
    for (size_t i = 1; i <= sizeof...(P); ++i) out[i] = out[i - 1] + arities[i];
    return out;
}
// Parameter P, made of the Python arguments at..at + arity<P> of `flat`.
template <class P, size_t At, class Flat, size_t... K>
decltype(auto) make(Taken& taken, Flat& flat, std::index_sequence<K...>) {
    return ParamOf<P>::from(taken, At, std::get<At + K>(flat)...);
}

// A function of the Python arguments A... that passes them on as a tuple (to body).
template <class Flat>
struct Python;
template <class... A>
struct Python<std::tuple<A...>> {
    template <class R, class Body>
    static auto function(Body body) {
        return [body](A... args) -> R { return body(std::forward_as_tuple(args...)); };
    }
};

// The names of the nb::arg among a def's extras, in order.
template <class Extra>
void add_name(std::vector<const char*>& names, const Extra& extra) {
    if constexpr (std::is_base_of_v<nb::arg, Extra> || std::is_base_of_v<nb::arg_v, Extra>) {
        names.push_back(extra.name_);
    }
}

template <bool Release, class R, class... P, size_t... I, class... Extra>
void def_kernel(nb::module_& m, const char* name, R (*kernel)(P...), std::index_sequence<I...>,
                const Extra&... extra) {
    using Flat = decltype(std::tuple_cat(std::declval<typename ParamOf<P>::Args>()...));
    std::vector<const char*> names;
    (add_name(names, extra), ...);
    if (names.size() != std::tuple_size_v<Flat>) throw std::logic_error(std::string(name));
    auto body = [kernel, names](auto flat) -> R {
        Taken taken{names.data(), {}};
        std::tuple<decltype(make<P, starts<P...>()[I]>(taken, flat,
                                                       std::make_index_sequence<arity<P>>{}))...>
            args{make<P, starts<P...>()[I]>(taken, flat, std::make_index_sequence<arity<P>>{})...};
        require_apart(taken.extents);
        if constexpr (Release) {
            nb::gil_scoped_release release;
            return std::apply(kernel, args);
        } else {
            return std::apply(kernel, args);
        }
    };
    m.def(name, Python<Flat>::template function<R>(body), extra...);
}

// Binds `kernel` (a function, or a lambda's + pointer) as `name`, its Python arguments
// named by the nb::arg among `extra`.
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
