// Structs of arrays declared once. Each struct's fields are one X-macro,
//
//     X(element type, dimensions, name, shape rule, doc)
//
// and everything else is made from it: the struct's members, the visitor over them, the
// check of a set of arrays against the shapes, their allocation, and (in the bindings)
// the names, namedtuples and type stub Python sees.
//
// A shape rule names each axis, separated by spaces: a number (that length), a name (a
// length shared by every array that names it: bound by the first array that has the
// axis, checked against the others), `name-k` (that length less k) or `_` (any length). Sizes holds
// the names' lengths, some known before the check (CAPACITY, say).
#pragma once

#include <cstdint>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace bearing::schema {

// The lengths of a shape rule's names, and which array bound each.
class Sizes {
public:
    Sizes() = default;
    Sizes(std::initializer_list<std::pair<std::string_view, int64_t>> known) {
        for (const auto& [name, value] : known) bind(name, value, "");
    }

    // The length of `name`, or nullptr while unbound.
    const int64_t* find(std::string_view name) const {
        for (const Entry& e : entries_) {
            if (e.name == name) return &e.value;
        }
        return nullptr;
    }
    int64_t at(std::string_view name) const {
        const int64_t* value = find(name);
        if (value == nullptr) {
            throw std::invalid_argument("no length is known for the axis " + std::string(name));
        }
        return *value;
    }
    // name's length is `value`, as the array `by` has it (a length bound before is replaced).
    void bind(std::string_view name, int64_t value, std::string_view by) {
        for (Entry& e : entries_) {
            if (e.name == name) {
                e = {std::string(name), value, std::string(by)};
                return;
            }
        }
        entries_.push_back({std::string(name), value, std::string(by)});
    }
    // The array that bound `name` ("" for a length known before the check).
    std::string_view bound_by(std::string_view name) const {
        for (const Entry& e : entries_) {
            if (e.name == name) return e.by;
        }
        return {};
    }

private:
    struct Entry {
        std::string name;
        int64_t value;
        std::string by;
    };
    std::vector<Entry> entries_;
};

namespace detail {

inline std::vector<std::string_view> split(std::string_view text, char separator) {
    std::vector<std::string_view> parts;
    size_t start = 0;
    while (start <= text.size()) {
        const size_t stop = std::min(text.find(separator, start), text.size());
        if (stop > start) parts.push_back(text.substr(start, stop - start));
        start = stop + 1;
    }
    return parts;
}

inline bool is_number(std::string_view token) {
    return !token.empty() && token.find_first_not_of("0123456789") == std::string_view::npos;
}

inline int64_t number(std::string_view token) {
    return std::strtoll(std::string(token).c_str(), nullptr, 10);
}

// A name and the amount `name-k` takes off it.
inline std::pair<std::string_view, int64_t> name_and_offset(std::string_view token) {
    const size_t minus = token.find('-');
    if (minus == std::string_view::npos) return {token, 0};
    return {token.substr(0, minus), number(token.substr(minus + 1))};
}

// The length an axis stands for, or false while its name is unbound.
inline bool known_length(std::string_view axis, const Sizes& sizes, int64_t& length) {
    if (is_number(axis)) {
        length = number(axis);
        return true;
    }
    const auto [name, offset] = name_and_offset(axis);
    const int64_t* value = sizes.find(name);
    if (value == nullptr) return false;
    length = *value - offset;
    return true;
}

}  // namespace detail

// Why `shape` (of `ndim` axes, the array `field`) does not follow `rule`, or "" if it
// does; the rule's unbound names are bound to its lengths.
inline std::string mismatch(std::string_view rule, const int64_t* shape, int ndim,
                            std::string_view field, Sizes& sizes) {
    const auto axes = detail::split(rule, ' ');
    if (static_cast<int>(axes.size()) != ndim) {
        return std::string(field) + " must have " + std::to_string(axes.size()) +
               " dimensions, not " + std::to_string(ndim);
    }
    for (int d = 0; d < ndim; ++d) {
        const std::string_view axis = axes[static_cast<size_t>(d)];
        int64_t length = 0;
        if (axis == "_") continue;
        if (!detail::known_length(axis, sizes, length)) {
            const auto [name, offset] = detail::name_and_offset(axis);
            sizes.bind(name, shape[d] + offset, field);
            continue;
        }
        if (length == shape[d]) continue;
        const std::string_view by = sizes.bound_by(detail::name_and_offset(axis).first);
        return std::string(field) + " has axis " + std::to_string(d) + " of length " +
               std::to_string(shape[d]) + ", expected " + std::string(axis) + " = " +
               std::to_string(length) + (by.empty() ? "" : ", as " + std::string(by) + " has it");
    }
    return {};
}

// Every array of the struct of arrays `s` follows its rule with `sizes`: otherwise
// std::invalid_argument naming the first that does not (label.field).
template <class Struct>
void check_shapes(const Struct& s, Sizes& sizes, const std::string& label) {
    for_each_field(s, [&](const char* name, const char* rule, const auto& view) {
        const int ndim = static_cast<int>(view.shape.size());
        const std::string why = mismatch(rule, view.shape.data(), ndim, label + "." + name, sizes);
        if (!why.empty()) throw std::invalid_argument(why);
    });
}

// The shape `rule` gives (`_` is 0), every name known: std::invalid_argument otherwise.
inline std::vector<int64_t> shape_of(std::string_view rule, const Sizes& sizes) {
    std::vector<int64_t> shape;
    for (std::string_view axis : detail::split(rule, ' ')) {
        int64_t length = 0;
        if (axis != "_" && !detail::known_length(axis, sizes, length)) {
            throw std::invalid_argument("no length is known for the axis " + std::string(axis));
        }
        shape.push_back(length);
    }
    return shape;
}

}  // namespace bearing::schema
