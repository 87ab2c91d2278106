// Copies of whole maps between batches (bearing_env/slam/batch.py's fill_from and take).
#include <bearing_core/slam/state.hpp>

#include <algorithm>

namespace bearing::slam {

namespace {

// to's row i = from's row rows[i], for one array (rows checked by the caller).
template <class T, int D>
void copy_rows(const View<T, D>& from, View1<const int64_t> rows, const View<T, D>& to) {
    const int64_t length = from.stride(0);
    for (int64_t i = 0; i < rows.shape[0]; ++i) {
        const T* source = from.row(rows[i]);
        std::copy(source, source + length, to.row(i));
    }
}

}  // namespace

void copy_maps(const MapState& from, View1<const int64_t> rows, const MapState& to) {
#define BEARING_CORE_COPY_FIELD(T, D, name, rule, doc) copy_rows(from.name, rows, to.name);
    BEARING_CORE_MAP_STATE(BEARING_CORE_COPY_FIELD)
#undef BEARING_CORE_COPY_FIELD
}

}  // namespace bearing::slam
