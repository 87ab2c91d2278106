// Turning Python arguments into checked views: every array the kernels take is checked
// once here (dtype, dimensions, C-contiguity, alignment, writeability, shape, bool bytes),
// and a bad one raises TypeError or ValueError naming the argument, never a crash. The
// library's structs of arrays (each declared once, as an X-macro) as Python sees them: read
// from a tuple or an object's attributes into checked views, new numpy arrays shaped by
// their rules, and their schema (names, dtypes, shape rules, docs) for the generated stub
// and namedtuples (tests/tools/generate_stubs.py).
#pragma once

#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>

#include <algorithm>
#include <cstdint>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <bearing_core/core/complex.hpp>
#include <bearing_core/core/schema.hpp>
#include <bearing_core/core/views.hpp>

namespace bearing::bindings {

namespace nb = nanobind;

// numpy's name of each element type the kernels take.
template <class T>
constexpr const char* dtype_name() {
    if constexpr (std::is_same_v<T, double>) return "float64";
    if constexpr (std::is_same_v<T, float>) return "float32";
    if constexpr (std::is_same_v<T, int64_t>) return "int64";
    if constexpr (std::is_same_v<T, int8_t>) return "int8";
    if constexpr (std::is_same_v<T, bool>) return "bool";
    if constexpr (std::is_same_v<T, cplx>) return "complex128";
    return "";  // (no other element type is bound)
}

template <class T>
nb::dlpack::dtype dtype_of() {
    if constexpr (std::is_same_v<T, cplx>) {
        return nb::dlpack::dtype{static_cast<uint8_t>(nb::dlpack::dtype_code::Complex), 128, 1};
    } else {
        return nb::dtype<T>();
    }
}

[[noreturn]] inline void type_error(const std::string& message) {
    throw nb::type_error(message.c_str());
}
[[noreturn]] inline void value_error(const std::string& message) {
    throw nb::value_error(message.c_str());
}

// A bool array's bytes are 0 or 1 (numpy writes no other, but a view of other bytes can
// hold any; the kernels would read such a byte as neither true nor false).
inline void check_bool_bytes(const bool* data, int64_t size, const char* name) {
    const auto* bytes = reinterpret_cast<const unsigned char*>(data);
    for (int64_t k = 0; k < size; ++k) {
        if (bytes[k] > 1) {
            value_error(std::string(name) + " holds the byte " + std::to_string(bytes[k]) +
                        " at flat index " + std::to_string(k) + ", not a bool (0 or 1)");
        }
    }
}

// A view of the numpy array `obj` (argument `name`): dtype T, D dimensions, C-contiguous,
// aligned for T, and writeable unless T is const; a read-only bool array (const bool)
// holds only 0 and 1 (a state's bool arrays, read and written, are checked by their
// parser, read_struct). Its shape is the caller's to check (a kernel's checked entry point,
// or the struct's schema).
template <class T, int D>
View<T, D> view_of(nb::handle obj, const char* name) {
    using Element = std::remove_const_t<T>;
    // Read-only arrays are taken too (nb::ro); a view of a non-const T checks writeability
    // below, naming the argument.
    nb::ndarray<nb::numpy, nb::ro> array;
    if (!nb::try_cast(obj, array, false)) {
        type_error(std::string(name) + " must be a numpy array, not " +
                   nb::type_name(obj.type()).c_str());
    }
    if (array.dtype() != dtype_of<Element>()) {
        type_error(std::string(name) + " must have dtype " + dtype_name<Element>());
    }
    if (static_cast<int>(array.ndim()) != D) {
        value_error(std::string(name) + " must have " + std::to_string(D) + " dimensions, not " +
                    std::to_string(array.ndim()));
    }
    View<T, D> view;
    int64_t expected_stride = 1;
    for (int d = D - 1; d >= 0; --d) {
        view.shape[d] = static_cast<int64_t>(array.shape(static_cast<size_t>(d)));
        // (An empty array is contiguous whatever its strides: numpy gives it zero strides.)
        if (array.size() > 0 && view.shape[d] > 1 &&
            array.stride(static_cast<size_t>(d)) != expected_stride) {
            value_error(std::string(name) + " must be C-contiguous");
        }
        expected_stride *= view.shape[d];
    }
    if constexpr (!std::is_const_v<T>) {
        if (array.size() > 0 && !nb::cast<bool>(obj.attr("flags").attr("writeable"))) {
            value_error(std::string(name) + " must be writeable");
        }
    }
    view.data = reinterpret_cast<T*>(const_cast<void*>(static_cast<const void*>(array.data())));
    if (reinterpret_cast<std::uintptr_t>(view.data) % alignof(Element) != 0) {
        value_error(std::string(name) + " must be aligned to " + std::to_string(alignof(Element)) +
                    " bytes (a view at an odd offset of a buffer is not)");
    }
    // (An output the kernel only writes may come from np.empty: its bytes are not read.)
    if constexpr (std::is_same_v<T, const bool>) check_bool_bytes(view.data, view.size(), name);
    return view;
}

// An array argument's memory, for require_apart.
struct Extent {
    const char* name;
    const void* data;
    int64_t bytes;
    bool written;  // the kernel writes it
};

template <class T, int D>
Extent extent_of(const View<T, D>& view, const char* name) {
    return {name, view.data, view.size() * static_cast<int64_t>(sizeof(T)), !std::is_const_v<T>};
}

// No array a kernel writes shares memory with another of its arguments: the kernels read
// their inputs while they write their outputs, so an overlap would change the result
// midway. ValueError naming both.
inline void require_apart(const std::vector<Extent>& arrays) {
    for (auto a = arrays.begin(); a != arrays.end(); ++a) {
        for (auto b = a + 1; b != arrays.end(); ++b) {
            if (!(a->written || b->written) || a->bytes == 0 || b->bytes == 0) continue;
            const auto* a_begin = static_cast<const char*>(a->data);
            const auto* b_begin = static_cast<const char*>(b->data);
            if (a_begin < b_begin + b->bytes && b_begin < a_begin + a->bytes) {
                value_error(std::string(a->name) + " and " + b->name +
                            " must not share memory (the kernel writes " +
                            (a->written ? a->name : b->name) + " while it reads the other)");
            }
        }
    }
}

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
