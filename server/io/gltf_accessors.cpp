// glTF 2.0 accessors for the loader of gltf_loader.hpp (glTF 2.0 §3.6 "Accessors" and §3.11
// "Implementation Note: Normalized data"): component types and sizes, one component as a double,
// byte ranges checked against buffer views and buffers, strides, sparse substitution. tinygltf does
// not bounds-check accessors; everything read from a buffer is checked here first.
#include "gltf_internal.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <utility>

namespace dermis::gltf_detail {
namespace {

/// Most components (elements × components per element) one accessor may hold: 5.5 million
/// VEC3 vertices. Bounds allocations for accessors without a buffer view (all zeros by the
/// spec), whose `count` nothing else limits.
constexpr std::size_t kMaxAccessorValues = std::size_t(1) << 24;

int componentSize(int componentType) {
    switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
        return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
        return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
        return 4;
    default:
        return 0; // DOUBLE and others are not glTF 2.0 component types
    }
}

int componentCount(int type) {
    switch (type) {
    case TINYGLTF_TYPE_SCALAR:
        return 1;
    case TINYGLTF_TYPE_VEC2:
        return 2;
    case TINYGLTF_TYPE_VEC3:
        return 3;
    case TINYGLTF_TYPE_VEC4:
        return 4;
    case TINYGLTF_TYPE_MAT2:
        return 4;
    case TINYGLTF_TYPE_MAT3:
        return 9;
    case TINYGLTF_TYPE_MAT4:
        return 16;
    default:
        return 0;
    }
}

const char* typeName(int type) {
    switch (type) {
    case TINYGLTF_TYPE_SCALAR:
        return "SCALAR";
    case TINYGLTF_TYPE_VEC2:
        return "VEC2";
    case TINYGLTF_TYPE_VEC3:
        return "VEC3";
    case TINYGLTF_TYPE_VEC4:
        return "VEC4";
    case TINYGLTF_TYPE_MAT2:
        return "MAT2";
    case TINYGLTF_TYPE_MAT3:
        return "MAT3";
    case TINYGLTF_TYPE_MAT4:
        return "MAT4";
    default:
        return "?";
    }
}

/// One component at `p` (any alignment), as a double; normalised integers map to [0, 1] or
/// [−1, 1] as in §3.11 (signed: max(c / (2^(b−1) − 1), −1)).
double readComponent(const unsigned char* p, int componentType, bool normalized) {
    switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
        std::int8_t v;
        std::memcpy(&v, p, 1);
        return normalized ? std::max(v / 127.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: {
        std::uint8_t v;
        std::memcpy(&v, p, 1);
        return normalized ? v / 255.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
        std::int16_t v;
        std::memcpy(&v, p, 2);
        return normalized ? std::max(v / 32767.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
        std::uint16_t v;
        std::memcpy(&v, p, 2);
        return normalized ? v / 65535.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
        std::uint32_t v;
        std::memcpy(&v, p, 4);
        return normalized ? v / 4294967295.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_FLOAT: {
        float v;
        std::memcpy(&v, p, 4);
        return v;
    }
    default:
        return 0.0;
    }
}

/// Start of `count` elements of `elemSize` bytes at `byteOffset` in buffer view `viewIndex`,
/// with the view's stride (or tight packing), checked to lie inside the view and its buffer.
Result<std::pair<const unsigned char*, std::size_t>>
locate(const tg::Model& g, int viewIndex, std::size_t byteOffset, std::size_t count,
       std::size_t elemSize, bool useViewStride, const std::string& field,
       const std::string& what) {
    if (viewIndex < 0 || static_cast<std::size_t>(viewIndex) >= g.bufferViews.size())
        return parseError(field, what + ": buffer view " + str(viewIndex) + " does not exist");
    const tg::BufferView& view = g.bufferViews[static_cast<std::size_t>(viewIndex)];
    if (view.buffer < 0 || static_cast<std::size_t>(view.buffer) >= g.buffers.size())
        return parseError(field, what + ": buffer view " + str(viewIndex) + " has no buffer");
    const std::vector<unsigned char>& data = g.buffers[static_cast<std::size_t>(view.buffer)].data;
    if (view.byteOffset > data.size() || view.byteLength > data.size() - view.byteOffset)
        return parseError(field,
                          what + ": buffer view " + str(viewIndex) + " lies outside its buffer");
    const std::size_t stride = useViewStride && view.byteStride != 0 ? view.byteStride : elemSize;
    if (stride < elemSize)
        return parseError(field,
                          what + ": byteStride " + str(stride) + " is smaller than an element");
    // count ≤ kMaxAccessorValues and stride ≤ 252, so the product cannot overflow.
    if (byteOffset > view.byteLength ||
        (count - 1) * stride + elemSize > view.byteLength - byteOffset)
        return parseError(field, what + ": reads past the end of buffer view " + str(viewIndex));
    return std::make_pair(data.data() + view.byteOffset + byteOffset, stride);
}

} // namespace

bool isIntegerType(int componentType) {
    return componentType != TINYGLTF_COMPONENT_TYPE_FLOAT && componentSize(componentType) > 0;
}

/// Reads accessor `index` of element type `type` (TINYGLTF_TYPE_*), checking every byte range,
/// the component type against `want` (and against `allowed` when non-empty), and sparse
/// substitution (§3.6.2.3). Errors name `field`, the place that references the accessor.
Result<AccessorData> readAccessor(const tg::Model& g, int index, int type, Want want,
                                  std::initializer_list<int> allowed, const std::string& field) {
    if (index < 0 || static_cast<std::size_t>(index) >= g.accessors.size())
        return parseError(field, "accessor " + str(index) + " does not exist");
    const tg::Accessor& a = g.accessors[static_cast<std::size_t>(index)];
    const std::string what = "accessor " + str(index);
    if (a.type != type)
        return parseError(field, what + " is " + typeName(a.type) + ", expected " + typeName(type));
    const int cs = componentSize(a.componentType);
    if (cs == 0) return parseError(field, what + ": invalid componentType " + str(a.componentType));
    if (allowed.size() != 0 &&
        std::find(allowed.begin(), allowed.end(), a.componentType) == allowed.end())
        return parseError(field, what + ": componentType " + str(a.componentType) +
                                     " is not allowed here");
    if (want == Want::Integer && (!isIntegerType(a.componentType) || a.normalized))
        return parseError(field, what + ": must hold unnormalised integers");
    // Matrices of 1- or 2-byte components have padded columns; glTF only uses float matrices.
    const bool matrix =
        type == TINYGLTF_TYPE_MAT2 || type == TINYGLTF_TYPE_MAT3 || type == TINYGLTF_TYPE_MAT4;
    if (matrix && a.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT)
        return parseError(field, what + ": matrices must be float");
    if (a.count > kMaxAccessorValues / static_cast<std::size_t>(componentCount(type)))
        return makeError(ErrorCode::Unsupported, kWhere, field,
                         what + ": " + str(a.count) + " elements is too many");

    AccessorData out;
    out.count = a.count;
    out.components = componentCount(type);
    out.componentType = a.componentType;
    out.normalized = a.normalized && isIntegerType(a.componentType);
    const std::size_t comps = static_cast<std::size_t>(out.components);
    const std::size_t elemSize = static_cast<std::size_t>(cs) * comps;
    out.values.assign(a.count * comps, 0.0); // no buffer view: zeros (§3.6.2.1)
    if (a.count == 0) return out;

    auto readElements = [&](const unsigned char* base, std::size_t stride, std::size_t n,
                            auto&& destination) {
        for (std::size_t e = 0; e < n; ++e) {
            const unsigned char* p = base + e * stride;
            double* d = destination(e);
            for (std::size_t c = 0; c < comps; ++c)
                d[c] = readComponent(p + c * static_cast<std::size_t>(cs), a.componentType,
                                     out.normalized);
        }
    };

    if (a.bufferView >= 0) {
        auto loc = locate(g, a.bufferView, a.byteOffset, a.count, elemSize, true, field, what);
        if (!loc) return loc.error();
        readElements(loc->first, loc->second, a.count,
                     [&](std::size_t e) { return &out.values[e * comps]; });
    } else if (a.bufferView != -1) {
        return parseError(field, what + ": buffer view " + str(a.bufferView) + " does not exist");
    }

    if (a.sparse.isSparse) {
        const auto& sp = a.sparse;
        const std::string swhat = what + " (sparse)";
        if (sp.count <= 0 || static_cast<std::size_t>(sp.count) > a.count)
            return parseError(field, swhat + ": count " + str(sp.count) + " out of range");
        const int ict = sp.indices.componentType;
        if (ict != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
            ict != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
            ict != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
            return parseError(field, swhat + ": invalid index componentType");
        if (sp.indices.byteOffset < 0 || sp.values.byteOffset < 0)
            return parseError(field, swhat + ": negative byteOffset");
        const auto n = static_cast<std::size_t>(sp.count);
        auto idx =
            locate(g, sp.indices.bufferView, static_cast<std::size_t>(sp.indices.byteOffset), n,
                   static_cast<std::size_t>(componentSize(ict)), false, field, swhat + " indices");
        if (!idx) return idx.error();
        auto val = locate(g, sp.values.bufferView, static_cast<std::size_t>(sp.values.byteOffset),
                          n, elemSize, false, field, swhat + " values");
        if (!val) return val.error();
        double previous = -1.0;
        std::vector<std::size_t> targets(n);
        for (std::size_t k = 0; k < n; ++k) {
            const double t = readComponent(idx->first + k * idx->second, ict, false);
            if (t <= previous || t >= static_cast<double>(a.count))
                return parseError(field, swhat + ": indices must increase and stay below count");
            previous = t;
            targets[k] = static_cast<std::size_t>(t);
        }
        readElements(val->first, val->second, n,
                     [&](std::size_t k) { return &out.values[targets[k] * comps]; });
    }
    return out;
}

/// Finite and within float range, so that converting to float is defined.
bool fitsFloat(double x) {
    return std::isfinite(x) && std::abs(x) <= double(std::numeric_limits<float>::max());
}

bool allFitFloat(const std::vector<double>& v) {
    return std::all_of(v.begin(), v.end(), fitsFloat);
}

} // namespace dermis::gltf_detail
