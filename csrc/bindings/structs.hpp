// The library's structs (each declared once, as an X-macro) as Python sees them: read from
// a tuple or an object's attributes into checked views, new numpy arrays shaped by their
// rules, and their schema (names, dtypes, shape rules, docs) for the generated stub and
// namedtuples (tests/tools/generate_stubs.py).
#pragma once

#include <nanobind/nanobind.h>

#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <bearing_core/core/schema.hpp>
#include <bearing_core/slam/checked.hpp>
#include "bindings/arrays.hpp"

namespace bearing::bindings {

// The Python objects a native object's views point into, kept alive with it.
using Kept = std::vector<nb::object>;

// The attribute `name` of `source` (`label` in messages): TypeError if it has none.
inline nb::object attribute(nb::handle source, const char* name, const char* label) {
    if (!nb::hasattr(source, name)) {
        type_error(std::string(label) + " (" + nb::type_name(source.type()).c_str() +
                   ") has no field '" + name + "'");
    }
    return source.attr(name);
}

template <class T>
T scalar_of(nb::handle source, const char* name, const char* label) {
    nb::object value = attribute(source, name, label);
    T result{};
    if (!nb::try_cast(value, result)) {
        type_error(std::string(label) + "." + name + " has the wrong type (" +
                   nb::type_name(value.type()).c_str() + ")");
    }
    return result;
}

template <class T, int D>
void read_field(View<T, D>& view, nb::handle value, const std::string& name, const char* rule,
                schema::Sizes& sizes, bool read_bools) {
    view = view_of<T, D>(value, name.c_str());
    const std::string why = schema::mismatch(rule, view.shape.data(), D, name, sizes);
    if (!why.empty()) value_error(why);
    // A bool array the kernels read holds only 0 and 1 (view_of checks read-only ones).
    if constexpr (std::is_same_v<T, bool>) {
        if (read_bools) check_bool_bytes(view.data, view.size(), name.c_str());
    }
}

template <class Struct>
size_t field_count() {
    size_t count = 0;
    for_each_field(Struct{}, [&](const char*, const char*, const auto&) { ++count; });
    return count;
}

// A struct of arrays' views of `source`: an object with its arrays as attributes (a
// namedtuple among them), or a plain tuple of them in order (`label` names it in messages:
// label.field, or the field alone for an empty label). Each array is checked (dtype,
// layout, alignment, writeability) and its shape against its rule with `sizes`, which
// binds the rule's names; with read_bools, its bool arrays' bytes too (the kernels read
// them; an output's are not read).
template <class Struct>
Struct read_struct(nb::handle source, const char* label, schema::Sizes& sizes, Kept& kept,
                   bool read_bools) {
    Struct out;
    const bool by_position = nb::isinstance<nb::tuple>(source) && !nb::hasattr(source, "_fields");
    if (by_position && nb::len(source) != field_count<Struct>()) {
        value_error(std::string(label) + " must hold " + std::to_string(field_count<Struct>()) +
                    " arrays, not " + std::to_string(nb::len(source)));
    }
    size_t k = 0;
    for_each_field(out, [&](const char* name, const char* rule, auto& view) {
        nb::object value = by_position ? nb::borrow(source[k++]) : attribute(source, name, label);
        const std::string qualified = *label != '\0' ? std::string(label) + "." + name : name;
        read_field(view, value, qualified, rule, sizes, read_bools);
        kept.push_back(std::move(value));
    });
    return out;
}

// New zero-filled numpy arrays for every field of `out`, shaped by the rules and `sizes`
// (every name known); `out` views them.
template <class Struct>
nb::tuple new_struct(const schema::Sizes& sizes, Struct& out) {
    nb::module_ numpy = nb::module_::import_("numpy");
    nb::list arrays;
    for_each_field(out, [&](const char* name, const char* rule, auto& view) {
        using Element = std::remove_pointer_t<decltype(view.data)>;
        constexpr int D = std::tuple_size_v<decltype(view.shape)>;
        nb::list shape;
        for (int64_t length : schema::shape_of(rule, sizes)) shape.append(length);
        nb::object array = numpy.attr("zeros")(nb::tuple(shape), dtype_name<Element>());
        view = view_of<Element, D>(array, name);
        arrays.append(array);
    });
    return nb::tuple(arrays);
}

// The schema of a struct of arrays: (name, dtype, shape rule, doc) per field, in order.
template <class Struct>
nb::tuple array_schema() {
    const Struct probe{};
    const std::vector<const char*> docs = field_docs(probe);
    nb::list fields;
    size_t k = 0;
    for_each_field(probe, [&](const char* name, const char* rule, const auto& view) {
        using Element = std::remove_const_t<std::remove_pointer_t<decltype(view.data)>>;
        fields.append(nb::make_tuple(name, dtype_name<Element>(), rule, docs[k++]));
    });
    return nb::tuple(fields);
}

// The Python type of a setting, as the schema names it (an enum's IntEnum, bound before).
template <class T>
nb::object python_type() {
    if constexpr (std::is_enum_v<T>) {
        return nb::type<T>().attr("__name__");
    } else if constexpr (std::is_same_v<T, bool>) {
        return nb::str("bool");
    } else {
        return nb::str(std::is_floating_point_v<T> ? "float" : "int");
    }
}

// A settings row of the schema: (name, Python type, "", doc).
#define BEARING_BINDINGS_SETTING_ROW(T, name, value, doc) \
    fields.append(nb::make_tuple(#name, bearing::bindings::python_type<T>(), "", doc));

}  // namespace bearing::bindings
