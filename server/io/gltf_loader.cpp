// glTF 2.0 loader of gltf_loader.hpp on tinygltf 2.7 (Debian's libtinygltf-dev, header only here).
//
// tinygltf parses the JSON and resolves buffers; everything this file then reads from a buffer is
// validated here (tinygltf does not bounds-check accessors). Three holes of tinygltf 2.7 are closed
// before it runs, because they crash or read out of bounds inside tinygltf itself on hostile input:
//   * the GLB container is checked here (tinygltf's BIN-chunk check forgets the 8-byte chunk
//     header);
//   * images stored in buffer views are bounds-checked against their buffer (tinygltf passes
//     &buffer.data[byteOffset] and byteLength to the image hook unchecked; fixed upstream by
//     tinygltf PR #512, after 2.7);
//   * JSON nesting is limited (tinygltf copies `extras` recursively and would overflow the stack).
// File access (external buffers and images of a .gltf) goes through callbacks confined to the
// model's folder: absolute URIs, "..", and symbolic links out of the folder are refused, and a
// model parsed from memory without a folder may not reference files at all.
#include <fstream> // tinygltf's writer needs it even with TINYGLTF_NO_FS
#define TINYGLTF_IMPLEMENTATION
#define TINYGLTF_NO_STB_IMAGE       // images are captured encoded (hook below), decoded by image_io
#define TINYGLTF_NO_STB_IMAGE_WRITE // this loader never writes glTF
#define TINYGLTF_NO_FS              // no default file access: only the confined callbacks below
#include <tiny_gltf.h>

#include "gltf_loader.hpp"

#include "core/rig.hpp"
#include "io/image_io.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <optional>

namespace dermis {
namespace {

namespace fs = std::filesystem;
namespace tg = tinygltf;

const char* const kWhere = "dermis::parseGltf";

/// Most components (elements × components per element) one accessor may hold: 5.5 million
/// VEC3 vertices. Bounds allocations for accessors without a buffer view (all zeros by the
/// spec), whose `count` nothing else limits.
constexpr std::size_t kMaxAccessorValues = std::size_t(1) << 24;
/// Deepest JSON nesting accepted (glTF itself needs about 8 levels; the rest is for extras).
constexpr int kMaxJsonDepth = 64;
/// Most influences a skin may have (MeshPart::joints holds 16-bit indices).
constexpr std::size_t kMaxSkinJoints = 65536;

Error parseError(const std::string& field, const std::string& what) {
    return makeError(ErrorCode::Parse, kWhere, field, what);
}

std::string str(std::size_t v) {
    return std::to_string(v);
}
std::string str(int v) {
    return std::to_string(v);
}

// ------------------------------------------------------------------------------------------------
// GLB container and JSON pre-flight (run before tinygltf sees the bytes)

std::uint32_t le32(const std::uint8_t* p) {
    return std::uint32_t(p[0]) | std::uint32_t(p[1]) << 8 | std::uint32_t(p[2]) << 16 |
           std::uint32_t(p[3]) << 24;
}

/// Where the parts of a GLB lie (glTF 2.0 §4.4 "Binary glTF Layout").
struct GlbView {
    std::size_t length = 0; ///< total length from the header (≤ the bytes given)
    std::size_t jsonOffset = 20;
    std::size_t jsonLength = 0;
};

/// Checks the 12-byte header and the chunk headers so that no chunk reaches past the data.
Result<GlbView> checkGlb(const std::vector<std::uint8_t>& b) {
    if (b.size() < 20) return parseError("", "truncated GLB header");
    const std::uint32_t version = le32(&b[4]);
    if (version != 2)
        return makeError(ErrorCode::Unsupported, kWhere, "",
                         "GLB container version " + std::to_string(version) + " (only 2)");
    GlbView v;
    v.length = le32(&b[8]);
    if (v.length > b.size())
        return parseError("", "truncated GLB: the header announces " + str(v.length) +
                                  " bytes, there are " + str(b.size()));
    if (v.length < 20) return parseError("", "GLB length smaller than its header");
    v.jsonLength = le32(&b[12]);
    if (le32(&b[16]) != 0x4E4F534Au) return parseError("", "the first GLB chunk is not JSON");
    if (v.jsonLength == 0 || v.jsonLength > v.length - 20)
        return parseError("", "the GLB JSON chunk reaches past the end of the file");
    const std::size_t end = 20 + v.jsonLength;
    if (end < v.length) {
        // A second chunk must be BIN (tinygltf reads only JSON + BIN); its 8-byte header and its
        // data must both fit.
        if (v.length - end < 8) return parseError("", "truncated GLB chunk header");
        const std::size_t binLength = le32(&b[end]);
        if (le32(&b[end + 4]) != 0x004E4942u)
            return parseError("", "the second GLB chunk is not BIN");
        if (binLength > v.length - end - 8)
            return parseError("", "the GLB BIN chunk reaches past the end of the file");
        if (binLength < 4 || binLength % 4 != 0)
            return parseError("", "the GLB BIN chunk length is not a positive multiple of 4");
    }
    return v;
}

/// Reads the JSON unsigned integer member `key` of object `o` into `out`; false when `o` is not
/// an object or the member is absent or of another type.
bool jsonUnsigned(const nlohmann::json& o, const char* key, std::uint64_t& out) {
    if (!o.is_object()) return false;
    auto it = o.find(key);
    if (it == o.end() || !it->is_number_unsigned()) return false;
    out = it->get<std::uint64_t>();
    return true;
}

/// Deepest nesting of arrays and objects in JSON text (brackets inside strings do not count).
/// Linear; meant for valid JSON, and harmless on anything else (the parser rejects that).
int jsonDepth(const char* text, std::size_t size) {
    int depth = 0, deepest = 0;
    bool inString = false;
    for (std::size_t i = 0; i < size; ++i) {
        const char c = text[i];
        if (inString) {
            if (c == '\\')
                ++i; // skip the escaped character
            else if (c == '"')
                inString = false;
        } else if (c == '"') {
            inString = true;
        } else if (c == '[' || c == '{') {
            deepest = std::max(deepest, ++depth);
        } else if (c == ']' || c == '}') {
            --depth;
        }
    }
    return deepest;
}

/// Checks what tinygltf reads unchecked while it parses: JSON nesting depth, the asset version,
/// required extensions, and the byte ranges of images stored in buffer views. Relies on tinygltf
/// giving every buffer exactly `byteLength` bytes (GLB, data URI and external file alike).
Status preflight(const char* json, std::size_t size) {
    // tinygltf copies `extras` and `extensions` recursively: deep nesting would overflow the stack.
    if (jsonDepth(json, size) > kMaxJsonDepth)
        return parseError("", "JSON nested deeper than " + str(kMaxJsonDepth) + " levels");
    const nlohmann::json doc = nlohmann::json::parse(json, json + size, nullptr, false);
    if (doc.is_discarded()) return parseError("", "not valid JSON");
    if (!doc.is_object()) return parseError("", "the glTF root is not a JSON object");

    auto asset = doc.find("asset");
    if (asset == doc.end() || !asset->is_object()) return parseError("/asset", "missing");
    auto version = asset->find("version");
    if (version == asset->end() || !version->is_string())
        return parseError("/asset/version", "missing");
    const std::string v = version->get<std::string>();
    if (v.rfind("2.", 0) != 0)
        return makeError(ErrorCode::Unsupported, kWhere, "/asset/version",
                         "glTF " + v + " (only 2.x)");

    // Extensions whose absence from this loader would change what is drawn are refused; these
    // are handled (quantized attributes are converted like any accessor) or harmless.
    if (auto req = doc.find("extensionsRequired"); req != doc.end() && req->is_array()) {
        for (std::size_t i = 0; i < req->size(); ++i) {
            const auto& e = (*req)[i];
            const std::string name = e.is_string() ? e.get<std::string>() : std::string("?");
            if (name != "KHR_mesh_quantization" && name != "KHR_materials_unlit")
                return makeError(ErrorCode::Unsupported, kWhere, "/extensionsRequired/" + str(i),
                                 "required extension " + name + " is not supported");
        }
    }

    auto images = doc.find("images");
    if (images == doc.end() || !images->is_array()) return Ok{};
    auto views = doc.find("bufferViews");
    auto buffers = doc.find("buffers");
    for (std::size_t i = 0; i < images->size(); ++i) {
        const auto& img = (*images)[i];
        if (!img.is_object() || !img.contains("bufferView")) continue;
        const std::string field = "/images/" + str(i) + "/bufferView";
        std::uint64_t view = 0, buffer = 0, bufLength = 0, offset = 0, length = 0;
        if (!jsonUnsigned(img, "bufferView", view) || views == doc.end() || !views->is_array() ||
            view >= views->size())
            return parseError(field, "no such buffer view");
        const auto& bv = (*views)[view];
        if (!jsonUnsigned(bv, "buffer", buffer) || buffers == doc.end() || !buffers->is_array() ||
            buffer >= buffers->size())
            return parseError(field, "the buffer view has no valid buffer");
        const bool offsetOk = !bv.contains("byteOffset") || jsonUnsigned(bv, "byteOffset", offset);
        if (!jsonUnsigned((*buffers)[buffer], "byteLength", bufLength) || !offsetOk ||
            !jsonUnsigned(bv, "byteLength", length) || length == 0 ||
            length > std::uint64_t(std::numeric_limits<int>::max()) || offset >= bufLength ||
            length > bufLength - offset)
            return parseError(field, "the image's buffer view lies outside its buffer");
    }
    return Ok{};
}

// ------------------------------------------------------------------------------------------------
// tinygltf callbacks: image capture and confined file access

/// Encoded image bytes by glTF image index, filled by the tinygltf image hook.
struct Captured {
    std::map<int, PendingImages::Entry> images;
};

bool captureImage(tg::Image* image, const int index, std::string* err, std::string*, int, int,
                  const unsigned char* bytes, int size, void* user) {
    if (bytes == nullptr || size <= 0) {
        if (err) *err += "image " + std::to_string(index) + " has no data\n";
        return false;
    }
    PendingImages::Entry e;
    e.gltfImage = index;
    e.bytes.assign(bytes, bytes + size);
    e.mimeType = image ? image->mimeType : std::string();
    static_cast<Captured*>(user)->images[index] = std::move(e);
    return true;
}

/// Where external resources may come from: a folder on disk (canonical `root`), or the named
/// files of an upload in memory (`memory`, seen by tinygltf under the virtual folder
/// kMemoryRoot); neither: no file access.
struct Sandbox {
    fs::path root;
    const GltfFiles* memory = nullptr;
};

/// The virtual folder of in-memory files (never touched on disk).
const char* const kMemoryRoot = "/dermis-upload";

/// `path` made canonical if it names something inside the sandbox's folder, else nullopt.
std::optional<fs::path> confined(const std::string& path, const Sandbox& sb) {
    if (sb.root.empty() || path.empty() || path.find('\0') != std::string::npos)
        return std::nullopt;
    std::error_code ec;
    const fs::path p = fs::weakly_canonical(fs::path(path), ec);
    if (ec) return std::nullopt;
    const auto [r, q] = std::mismatch(sb.root.begin(), sb.root.end(), p.begin(), p.end());
    if (r != sb.root.end() || q == p.end()) return std::nullopt;
    return p;
}

/// The in-memory file `path` names: "<kMemoryRoot>/<name>" exactly, no folders, no "..".
const std::vector<std::uint8_t>* memoryFile(const std::string& path, const Sandbox& sb) {
    if (!sb.memory || path.find('\0') != std::string::npos) return nullptr;
    const fs::path p = fs::path(path).lexically_normal();
    if (p.parent_path() != fs::path(kMemoryRoot)) return nullptr;
    const auto it = sb.memory->find(p.filename().string());
    return it == sb.memory->end() ? nullptr : &it->second;
}

bool sandboxFileExists(const std::string& path, void* user) {
    const Sandbox& sb = *static_cast<Sandbox*>(user);
    if (sb.memory) return memoryFile(path, sb) != nullptr;
    const auto p = confined(path, sb);
    std::error_code ec;
    return p && fs::is_regular_file(*p, ec);
}

std::string sandboxExpand(const std::string& path, void*) {
    return path;
}

bool sandboxRead(std::vector<unsigned char>* out, std::string* err, const std::string& path,
                 void* user) {
    const Sandbox& sb = *static_cast<Sandbox*>(user);
    if (sb.memory) {
        const auto* bytes = memoryFile(path, sb);
        if (!bytes || bytes->size() > kMaxGltfBytes) {
            if (err) *err += "refused or not among the uploaded files: " + path + "\n";
            return false;
        }
        out->assign(bytes->begin(), bytes->end());
        return true;
    }
    const auto p = confined(path, sb);
    std::error_code ec;
    const auto size = p ? fs::file_size(*p, ec) : 0;
    if (!p || ec || !fs::is_regular_file(*p, ec) || size > kMaxGltfBytes) {
        if (err) *err += "refused or unreadable: " + path + "\n";
        return false;
    }
    std::ifstream in(*p, std::ios::binary);
    out->resize(static_cast<std::size_t>(size));
    in.read(reinterpret_cast<char*>(out->data()), static_cast<std::streamsize>(size));
    if (!in) {
        if (err) *err += "cannot read: " + path + "\n";
        return false;
    }
    return true;
}

bool sandboxWrite(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
    if (err) *err += "writing is disabled\n";
    return false;
}

// ------------------------------------------------------------------------------------------------
// Accessors (glTF 2.0 §3.6 "Accessors" and §3.11 "Implementation Note: Normalized data")

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

bool isIntegerType(int componentType) {
    return componentType != TINYGLTF_COMPONENT_TYPE_FLOAT && componentSize(componentType) > 0;
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

/// How an accessor's components are delivered.
enum class Want {
    Float,   ///< any component type; normalised integers per §3.11, others as their value
    Integer, ///< unsigned integer component types only, not normalised (indices, JOINTS_n)
};

/// Accessor contents: count × components values, row by row.
struct AccessorData {
    std::size_t count = 0;
    int components = 0;
    int componentType = 0;
    bool normalized = false;
    std::vector<double> values;
    double at(std::size_t element, int component) const {
        return values[element * static_cast<std::size_t>(components) +
                      static_cast<std::size_t>(component)];
    }
};

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

// ------------------------------------------------------------------------------------------------
// Model conversion

/// TRS of an affine column-major matrix without shear (glTF 2.0 §3.5.2 requires node matrices
/// to be decomposable so): T from column 3, S from the column lengths, R from the normalised
/// columns. A mirrored matrix (negative determinant) gets a negative x scale; a matrix with a
/// zero scale gets the identity rotation. False for projective matrices and for values outside
/// float range. (Written out rather than with glm::decompose, an experimental GLM extension that
/// divides by the column lengths and so returns NaN for a zero scale.)
bool decomposeTRS(const glm::dmat4& m, glm::vec3& t, glm::quat& r, glm::vec3& s) {
    if (std::abs(m[0][3]) > 1e-6 || std::abs(m[1][3]) > 1e-6 || std::abs(m[2][3]) > 1e-6 ||
        std::abs(m[3][3] - 1.0) > 1e-6)
        return false; // projective: not a TRS
    glm::dvec3 cols[3] = {glm::dvec3(m[0]), glm::dvec3(m[1]), glm::dvec3(m[2])};
    glm::dvec3 scale(glm::length(cols[0]), glm::length(cols[1]), glm::length(cols[2]));
    if (glm::dot(cols[0], glm::cross(cols[1], cols[2])) < 0.0) scale.x = -scale.x;
    glm::dmat3 rot(1.0);
    if (scale.x != 0.0 && scale.y != 0.0 && scale.z != 0.0)
        rot = glm::dmat3(cols[0] / scale.x, cols[1] / scale.y, cols[2] / scale.z);
    const glm::dquat q = glm::normalize(glm::quat_cast(rot));
    const glm::dvec3 translation(m[3]);
    for (int k = 0; k < 3; ++k)
        if (!fitsFloat(translation[k]) || !fitsFloat(scale[k])) return false;
    for (int k = 0; k < 4; ++k)
        if (!std::isfinite(q[k])) return false;
    t = glm::vec3(translation);
    r = glm::quat(q);
    s = glm::vec3(scale);
    return true;
}

/// glTF → Model, validating everything it reads.
class Converter {
  public:
    Converter(const tg::Model& g, Captured& captured) : g_(g), captured_(captured) {}

    Result<ParsedGltf> run() {
        if (auto s = nodes(); !s) return s.error();
        if (auto s = skins(); !s) return s.error();
        if (auto s = materials(); !s) return s.error();
        if (auto s = meshes(); !s) return s.error();
        if (auto s = animations(); !s) return s.error();
        ParsedGltf out;
        out.model = std::move(m_);
        out.images = std::move(pending_);
        return out;
    }

  private:
    const tg::Model& g_;
    Captured& captured_;
    Model m_;
    PendingImages pending_;
    std::vector<std::vector<Influence>> skinInfluences_;
    std::vector<glm::mat4> restWorld_;

    // --- nodes: names, rest TRS, parents -----------------------------------------------------
    Status nodes() {
        const std::size_t n = g_.nodes.size();
        m_.nodes.resize(n);
        for (std::size_t i = 0; i < n; ++i) {
            const tg::Node& src = g_.nodes[i];
            Node& dst = m_.nodes[i];
            const std::string field = "/nodes/" + str(i);
            dst.name = src.name;
            if (!src.matrix.empty()) {
                if (src.matrix.size() != 16 || !allFitFloat(src.matrix))
                    return parseError(field + "/matrix", "must be 16 finite float numbers");
                glm::dmat4 mat;
                for (int c = 0; c < 4; ++c)
                    for (int r = 0; r < 4; ++r)
                        mat[c][r] = src.matrix[static_cast<std::size_t>(c * 4 + r)];
                if (!decomposeTRS(mat, dst.translation, dst.rotation, dst.scale))
                    return parseError(field + "/matrix", "is not a translation·rotation·scale");
            } else {
                if (!src.translation.empty()) {
                    if (src.translation.size() != 3 || !allFitFloat(src.translation))
                        return parseError(field + "/translation", "must be 3 finite float numbers");
                    dst.translation = glm::vec3(
                        glm::dvec3(src.translation[0], src.translation[1], src.translation[2]));
                }
                if (!src.rotation.empty()) {
                    if (src.rotation.size() != 4 || !allFitFloat(src.rotation))
                        return parseError(field + "/rotation", "must be 4 finite float numbers");
                    const glm::dquat q(src.rotation[3], src.rotation[0], src.rotation[1],
                                       src.rotation[2]);
                    const double len = glm::length(q);
                    if (!(len > 1e-6) || !std::isfinite(len))
                        return parseError(field + "/rotation", "is not a unit quaternion");
                    dst.rotation = glm::quat(q / len);
                }
                if (!src.scale.empty()) {
                    if (src.scale.size() != 3 || !allFitFloat(src.scale))
                        return parseError(field + "/scale", "must be 3 finite float numbers");
                    dst.scale = glm::vec3(glm::dvec3(src.scale[0], src.scale[1], src.scale[2]));
                }
            }
        }
        // Parents from children: each node has at most one parent and is not its own ancestor
        // (glTF 2.0 §3.5.3: the node hierarchy is a set of disjoint strict trees).
        for (std::size_t i = 0; i < n; ++i) {
            const auto& children = g_.nodes[i].children;
            for (std::size_t k = 0; k < children.size(); ++k) {
                const int c = children[k];
                const std::string field = "/nodes/" + str(i) + "/children/" + str(k);
                if (c < 0 || static_cast<std::size_t>(c) >= n)
                    return parseError(field, "node " + str(c) + " does not exist");
                if (static_cast<std::size_t>(c) == i)
                    return parseError(field, "a node cannot be its own child");
                if (m_.nodes[c].parent != -1)
                    return parseError(field, "node " + str(c) + " has more than one parent");
                m_.nodes[c].parent = static_cast<int>(i);
            }
        }
        // Cycles, in linear time: walk up from each node until a node already known to lead to
        // a root (2); meeting a node of the current walk (1) closes a cycle.
        std::vector<unsigned char> state(n, 0);
        std::vector<std::size_t> walk;
        for (std::size_t i = 0; i < n; ++i) {
            walk.clear();
            std::size_t k = i;
            while (state[k] == 0) {
                state[k] = 1;
                walk.push_back(k);
                if (m_.nodes[k].parent < 0) break;
                k = static_cast<std::size_t>(m_.nodes[k].parent);
            }
            if (state[k] == 1 && m_.nodes[k].parent >= 0)
                return parseError("/nodes/" + str(k), "the node hierarchy has a cycle");
            for (std::size_t w : walk)
                state[w] = 2;
        }
        restWorld_ = worldMatrices(m_, restPose(m_));
        return Ok{};
    }

    // --- skins: joints and inverse bind matrices ----------------------------------------------
    Status skins() {
        for (std::size_t s = 0; s < g_.skins.size(); ++s) {
            const tg::Skin& skin = g_.skins[s];
            const std::string field = "/skins/" + str(s);
            if (skin.joints.empty()) return parseError(field + "/joints", "no joints");
            if (skin.joints.size() > kMaxSkinJoints)
                return makeError(ErrorCode::Unsupported, kWhere, field + "/joints",
                                 "more than " + str(kMaxSkinJoints) + " joints");
            std::vector<Influence> infl(skin.joints.size());
            for (std::size_t k = 0; k < skin.joints.size(); ++k) {
                const int j = skin.joints[k];
                if (j < 0 || static_cast<std::size_t>(j) >= m_.nodes.size())
                    return parseError(field + "/joints/" + str(k),
                                      "node " + str(j) + " does not exist");
                infl[k].node = j;
                if (std::find(m_.joints.begin(), m_.joints.end(), j) == m_.joints.end())
                    m_.joints.push_back(j);
            }
            if (skin.inverseBindMatrices >= 0) {
                const std::string f = field + "/inverseBindMatrices";
                auto ibm = readAccessor(g_, skin.inverseBindMatrices, TINYGLTF_TYPE_MAT4,
                                        Want::Float, {TINYGLTF_COMPONENT_TYPE_FLOAT}, f);
                if (!ibm) return ibm.error();
                if (ibm->count < infl.size()) return parseError(f, "fewer matrices than joints");
                if (!allFitFloat(ibm->values)) return parseError(f, "non-finite value");
                for (std::size_t k = 0; k < infl.size(); ++k)
                    for (int c = 0; c < 4; ++c)
                        for (int r = 0; r < 4; ++r)
                            infl[k].inverseBind[c][r] = static_cast<float>(ibm->at(k, c * 4 + r));
            }
            skinInfluences_.push_back(std::move(infl));
        }
        return Ok{};
    }

    // --- materials: base colour factor and texture → compact Model::images --------------------
    Status materials() {
        std::map<int, int> imageSlot; // glTF image → index in Model::images
        for (std::size_t i = 0; i < g_.materials.size(); ++i) {
            const tg::Material& src = g_.materials[i];
            const std::string field = "/materials/" + str(i) + "/pbrMetallicRoughness";
            Material dst;
            dst.name = src.name;
            const auto& f = src.pbrMetallicRoughness.baseColorFactor;
            if (!f.empty()) {
                if (f.size() != 4 || !allFitFloat(f))
                    return parseError(field + "/baseColorFactor", "must be 4 finite float numbers");
                dst.baseColorFactor = glm::vec4(glm::dvec4(f[0], f[1], f[2], f[3]));
            }
            const int tex = src.pbrMetallicRoughness.baseColorTexture.index;
            if (tex >= 0) {
                if (static_cast<std::size_t>(tex) >= g_.textures.size())
                    return parseError(field + "/baseColorTexture/index",
                                      "texture " + str(tex) + " does not exist");
                const int image = g_.textures[static_cast<std::size_t>(tex)].source;
                if (image >= 0) {
                    if (static_cast<std::size_t>(image) >= g_.images.size())
                        return parseError("/textures/" + str(tex) + "/source",
                                          "image " + str(image) + " does not exist");
                    auto [it, inserted] =
                        imageSlot.emplace(image, static_cast<int>(imageSlot.size()));
                    if (inserted) {
                        auto cap = captured_.images.find(image);
                        if (cap == captured_.images.end())
                            return makeError(ErrorCode::NotFound, kWhere, "/images/" + str(image),
                                             "image data not available (external file missing "
                                             "or outside the model's folder)");
                        PendingImages::Entry e = std::move(cap->second);
                        e.imageIndex = it->second;
                        pending_.entries.push_back(std::move(e));
                    }
                    dst.baseColorTexture = it->second;
                }
                // A texture with no core `source` (e.g. only KHR_texture_basisu): untextured.
            }
            m_.materials.push_back(std::move(dst));
        }
        m_.images.resize(imageSlot.size());
        return Ok{};
    }

    // --- meshes of the default scene --------------------------------------------------------
    Status meshes() {
        // Roots: the default scene, else scene 0, else every parentless node.
        std::vector<int> roots;
        if (!g_.scenes.empty()) {
            int scene = g_.defaultScene;
            if (scene < 0) scene = 0;
            if (static_cast<std::size_t>(scene) >= g_.scenes.size())
                return parseError("/scene", "scene " + str(scene) + " does not exist");
            const auto& list = g_.scenes[static_cast<std::size_t>(scene)].nodes;
            for (std::size_t k = 0; k < list.size(); ++k) {
                if (list[k] < 0 || static_cast<std::size_t>(list[k]) >= m_.nodes.size())
                    return parseError("/scenes/" + str(scene) + "/nodes/" + str(k),
                                      "node " + str(list[k]) + " does not exist");
                roots.push_back(list[k]);
            }
        } else {
            for (std::size_t i = 0; i < m_.nodes.size(); ++i)
                if (m_.nodes[i].parent < 0) roots.push_back(static_cast<int>(i));
        }
        // Depth-first, children in file order; each node once.
        std::vector<char> seen(m_.nodes.size(), 0);
        std::vector<int> stack(roots.rbegin(), roots.rend());
        while (!stack.empty()) {
            const int i = stack.back();
            stack.pop_back();
            if (seen[static_cast<std::size_t>(i)]) continue;
            seen[static_cast<std::size_t>(i)] = 1;
            if (auto s = meshNode(i); !s) return s.error();
            const auto& children = g_.nodes[static_cast<std::size_t>(i)].children;
            for (auto it = children.rbegin(); it != children.rend(); ++it)
                stack.push_back(*it);
        }
        return Ok{};
    }

    Status meshNode(int nodeIndex) {
        const tg::Node& node = g_.nodes[static_cast<std::size_t>(nodeIndex)];
        const std::string nodeField = "/nodes/" + str(nodeIndex);
        if (node.mesh < 0) return Ok{};
        if (static_cast<std::size_t>(node.mesh) >= g_.meshes.size())
            return parseError(nodeField + "/mesh", "mesh " + str(node.mesh) + " does not exist");
        if (node.skin >= 0 && static_cast<std::size_t>(node.skin) >= g_.skins.size())
            return parseError(nodeField + "/skin", "skin " + str(node.skin) + " does not exist");
        const tg::Mesh& mesh = g_.meshes[static_cast<std::size_t>(node.mesh)];
        for (std::size_t p = 0; p < mesh.primitives.size(); ++p) {
            const std::string field = "/meshes/" + str(node.mesh) + "/primitives/" + str(p);
            std::string name = !mesh.name.empty() ? mesh.name : node.name;
            if (mesh.primitives.size() > 1) name += "#" + str(p);
            if (auto s = primitive(nodeIndex, mesh.primitives[p], field, name); !s)
                return s.error();
        }
        return Ok{};
    }

    /// Reads the attribute `name` of `prim` (nullopt when absent), checking its vertex count.
    Result<std::optional<AccessorData>> attribute(const tg::Primitive& prim,
                                                  const std::string& name, int type, Want want,
                                                  std::initializer_list<int> allowed,
                                                  const std::string& primField,
                                                  std::size_t vertexCount) {
        auto it = prim.attributes.find(name);
        if (it == prim.attributes.end()) return std::optional<AccessorData>();
        const std::string field = primField + "/attributes/" + name;
        auto data = readAccessor(g_, it->second, type, want, allowed, field);
        if (!data) return data.error();
        if (vertexCount != 0 && data->count != vertexCount)
            return parseError(field,
                              str(data->count) + " elements, POSITION has " + str(vertexCount));
        if (!allFitFloat(data->values)) return parseError(field, "non-finite value");
        return std::optional<AccessorData>(std::move(*data));
    }

    Status primitive(int nodeIndex, const tg::Primitive& prim, const std::string& field,
                     const std::string& name) {
        // Topology (glTF 2.0 §3.7.2.1): lists, strips and fans become lists; points and lines
        // are not surfaces and are skipped.
        const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
        if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
            mode != TINYGLTF_MODE_TRIANGLE_FAN) {
            if (mode >= TINYGLTF_MODE_POINTS && mode < TINYGLTF_MODE_TRIANGLES) return Ok{};
            return parseError(field + "/mode", "invalid mode " + str(mode));
        }
        if (prim.material >= 0 && static_cast<std::size_t>(prim.material) >= m_.materials.size())
            return parseError(field + "/material",
                              "material " + str(prim.material) + " does not exist");
        if (prim.material < -1)
            return parseError(field + "/material", "invalid index " + str(prim.material));

        MeshPart part;
        part.name = name;
        part.material = prim.material;

        // POSITION
        auto pos = attribute(prim, "POSITION", TINYGLTF_TYPE_VEC3, Want::Float, {}, field, 0);
        if (!pos) return pos.error();
        if (!*pos) return parseError(field + "/attributes/POSITION", "missing");
        const std::size_t nv = (*pos)->count;
        if (nv == 0) return parseError(field + "/attributes/POSITION", "no vertices");
        part.positions.resize(nv);
        for (std::size_t v = 0; v < nv; ++v)
            part.positions[v] =
                glm::vec3(glm::dvec3((*pos)->at(v, 0), (*pos)->at(v, 1), (*pos)->at(v, 2)));
        for (const glm::vec3& p : part.positions)
            if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
                return parseError(field + "/attributes/POSITION", "value out of float range");

        // Indices → triangle list.
        std::vector<std::uint32_t> raw;
        if (prim.indices >= 0) {
            const std::string f = field + "/indices";
            auto idx = readAccessor(g_, prim.indices, TINYGLTF_TYPE_SCALAR, Want::Integer,
                                    {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                                     TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT,
                                     TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT},
                                    f);
            if (!idx) return idx.error();
            raw.resize(idx->count);
            for (std::size_t k = 0; k < idx->count; ++k) {
                const double v = idx->values[k];
                if (v >= static_cast<double>(nv))
                    return parseError(f, "index " + str(static_cast<std::size_t>(v)) +
                                             " out of range (" + str(nv) + " vertices)");
                raw[k] = static_cast<std::uint32_t>(v);
            }
        } else {
            raw.resize(nv);
            for (std::size_t k = 0; k < nv; ++k)
                raw[k] = static_cast<std::uint32_t>(k);
        }
        if (mode == TINYGLTF_MODE_TRIANGLES) {
            if (raw.size() % 3 != 0)
                return parseError(prim.indices >= 0 ? field + "/indices"
                                                    : field + "/attributes/POSITION",
                                  str(raw.size()) + " vertices is not a whole number of "
                                                    "triangles");
            part.indices = std::move(raw);
        } else if (raw.size() >= 3) {
            part.indices.reserve((raw.size() - 2) * 3);
            for (std::size_t i = 0; i + 2 < raw.size(); ++i) {
                if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
                    // {v_i, v_{i+(1+i%2)}, v_{i+(2−i%2)}}: every other triangle flips.
                    part.indices.insert(part.indices.end(),
                                        {raw[i], raw[i + 1 + i % 2], raw[i + 2 - i % 2]});
                } else {
                    part.indices.insert(part.indices.end(), {raw[i + 1], raw[i + 2], raw[0]});
                }
            }
        }

        // NORMAL (unit; computed where missing or zero)
        auto nrm = attribute(prim, "NORMAL", TINYGLTF_TYPE_VEC3, Want::Float, {}, field, nv);
        if (!nrm) return nrm.error();
        {
            std::vector<glm::vec3> computed;
            part.normals.resize(nv);
            for (std::size_t v = 0; v < nv; ++v) {
                glm::dvec3 n(0.0);
                if (*nrm) n = glm::dvec3((*nrm)->at(v, 0), (*nrm)->at(v, 1), (*nrm)->at(v, 2));
                const double len = glm::length(n);
                if (len > 1e-12) {
                    part.normals[v] = glm::vec3(n / len);
                } else {
                    if (computed.empty()) computed = computeNormals(part.positions, part.indices);
                    part.normals[v] = computed[v];
                }
            }
        }

        // TEXCOORD_0
        auto uv = attribute(prim, "TEXCOORD_0", TINYGLTF_TYPE_VEC2, Want::Float, {}, field, nv);
        if (!uv) return uv.error();
        if (*uv) {
            part.uvs.resize(nv);
            for (std::size_t v = 0; v < nv; ++v)
                part.uvs[v] = glm::vec2(glm::dvec2((*uv)->at(v, 0), (*uv)->at(v, 1)));
        }

        // Skinned (node has a skin and the primitive has JOINTS_0), else rigid on the node.
        const tg::Node& node = g_.nodes[static_cast<std::size_t>(nodeIndex)];
        const bool skinned = node.skin >= 0 && prim.attributes.count("JOINTS_0") != 0;
        if (skinned) {
            if (auto s = skinWeights(prim, field, static_cast<std::size_t>(node.skin), part); !s)
                return s.error();
        } else if (auto s = rigid(nodeIndex, part); !s) {
            return s.error();
        }
        m_.parts.push_back(std::move(part));
        return Ok{};
    }

    /// JOINTS_n / WEIGHTS_n → the 4 largest influences per vertex, weights normalised (an
    /// all-zero vertex gets weight 1 on influence 0).
    Status skinWeights(const tg::Primitive& prim, const std::string& field, std::size_t skin,
                       MeshPart& part) {
        const std::size_t nv = part.positions.size();
        part.influences = skinInfluences_[skin];
        std::vector<AccessorData> joints, weights;
        for (int set = 0;; ++set) {
            const std::string jn = "JOINTS_" + std::to_string(set);
            const std::string wn = "WEIGHTS_" + std::to_string(set);
            auto j = attribute(
                prim, jn, TINYGLTF_TYPE_VEC4, Want::Integer,
                {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT},
                field, nv);
            if (!j) return j.error();
            auto w =
                attribute(prim, wn, TINYGLTF_TYPE_VEC4, Want::Float,
                          {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                           TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT},
                          field, nv);
            if (!w) return w.error();
            if (!*j && !*w) break;
            if (!*j || !*w)
                return parseError(field + "/attributes/" + (*j ? wn : jn),
                                  "missing (JOINTS_n and WEIGHTS_n come in pairs)");
            if (isIntegerType((*w)->componentType) && !(*w)->normalized)
                return parseError(field + "/attributes/" + wn,
                                  "integer weights must be normalized");
            joints.push_back(std::move(**j));
            weights.push_back(std::move(**w));
        }
        const std::size_t sets = joints.size();
        const std::size_t influenceCount = part.influences.size();
        part.joints.resize(nv);
        part.weights.resize(nv);
        std::vector<std::pair<double, std::size_t>> cand; // (weight, joint)
        for (std::size_t v = 0; v < nv; ++v) {
            cand.clear();
            for (std::size_t s = 0; s < sets; ++s) {
                for (int c = 0; c < 4; ++c) {
                    const double w = weights[s].at(v, c);
                    if (!(w > 0.0)) continue; // zero (or negative) weights do not count
                    const double j = joints[s].at(v, c);
                    if (j >= static_cast<double>(influenceCount))
                        return parseError(
                            field + "/attributes/JOINTS_" + str(s),
                            "vertex " + str(v) + ": joint " + str(static_cast<std::size_t>(j)) +
                                " out of range (skin has " + str(influenceCount) + ")");
                    cand.emplace_back(w, static_cast<std::size_t>(j));
                }
            }
            if (cand.size() > 4) {
                std::partial_sort(cand.begin(), cand.begin() + 4, cand.end(),
                                  [](const auto& a, const auto& b) { return a.first > b.first; });
                cand.resize(4);
            }
            double sum = 0.0;
            for (const auto& c : cand)
                sum += c.first;
            glm::u16vec4 jv(0);
            glm::vec4 wv(0.0f);
            if (!(sum > 0.0)) {
                wv.x = 1.0f; // no weight at all: follow influence 0
            } else {
                for (std::size_t k = 0; k < cand.size(); ++k) {
                    jv[static_cast<int>(k)] = static_cast<std::uint16_t>(cand[k].second);
                    wv[static_cast<int>(k)] = static_cast<float>(cand[k].first / sum);
                }
            }
            part.joints[v] = jv;
            part.weights[v] = wv;
        }
        return Ok{};
    }

    /// A mesh on a plain node: positions and normals baked into rest world space, one influence
    /// {node, inverse(restWorld(node))} (see MeshPart). When the rest world matrix is singular
    /// (a node scaled to zero at rest) the part stays in the node's local space with an identity
    /// inverse bind: posed positions are the same, only the bind space differs.
    Status rigid(int nodeIndex, MeshPart& part) {
        const glm::mat4 world = restWorld_[static_cast<std::size_t>(nodeIndex)];
        const glm::dmat4 dworld(world);
        const double det = glm::determinant(glm::dmat3(dworld));
        Influence inf;
        inf.node = nodeIndex;
        if (det != 0.0 && std::isfinite(det)) {
            const glm::dmat4 inverse = glm::inverse(dworld);
            bool ok = true;
            for (int c = 0; c < 4; ++c)
                for (int r = 0; r < 4; ++r)
                    ok = ok && fitsFloat(inverse[c][r]);
            if (ok) {
                inf.inverseBind = glm::mat4(inverse);
                const glm::dmat3 nm = glm::transpose(glm::inverse(glm::dmat3(dworld)));
                for (std::size_t v = 0; v < part.positions.size(); ++v) {
                    const glm::dvec3 p(dworld * glm::dvec4(glm::dvec3(part.positions[v]), 1.0));
                    if (!fitsFloat(p.x) || !fitsFloat(p.y) || !fitsFloat(p.z))
                        return parseError("/nodes/" + str(nodeIndex),
                                          "the rest transform takes the mesh out of float range");
                    part.positions[v] = glm::vec3(p);
                    const glm::dvec3 n = nm * glm::dvec3(part.normals[v]);
                    const double len = glm::length(n);
                    if (len > 0.0 && std::isfinite(len)) part.normals[v] = glm::vec3(n / len);
                }
            }
        }
        part.influences = {inf};
        part.joints.assign(part.positions.size(), glm::u16vec4(0));
        part.weights.assign(part.positions.size(), glm::vec4(1.0f, 0.0f, 0.0f, 0.0f));
        return Ok{};
    }

    // --- animations -------------------------------------------------------------------------
    Status animations() {
        for (std::size_t a = 0; a < g_.animations.size(); ++a) {
            const tg::Animation& anim = g_.animations[a];
            const std::string field = "/animations/" + str(a);
            Clip clip;
            clip.name = anim.name.empty() ? "animation" + str(a) : anim.name;
            for (std::size_t c = 0; c < anim.channels.size(); ++c) {
                const tg::AnimationChannel& ch = anim.channels[c];
                const std::string cfield = field + "/channels/" + str(c);
                ChannelPath path;
                if (ch.target_path == "translation")
                    path = ChannelPath::Translation;
                else if (ch.target_path == "rotation")
                    path = ChannelPath::Rotation;
                else if (ch.target_path == "scale")
                    path = ChannelPath::Scale;
                else
                    continue; // "weights" (morph targets) and extension paths: not loaded
                if (ch.target_node < 0) continue; // targeted by an extension only
                if (static_cast<std::size_t>(ch.target_node) >= m_.nodes.size())
                    return parseError(cfield + "/target/node",
                                      "node " + str(ch.target_node) + " does not exist");
                if (ch.sampler < 0 || static_cast<std::size_t>(ch.sampler) >= anim.samplers.size())
                    return parseError(cfield + "/sampler",
                                      "sampler " + str(ch.sampler) + " does not exist");
                const tg::AnimationSampler& smp =
                    anim.samplers[static_cast<std::size_t>(ch.sampler)];
                const std::string sfield = field + "/samplers/" + str(ch.sampler);
                Channel out;
                out.node = ch.target_node;
                out.path = path;
                if (smp.interpolation == "LINEAR" || smp.interpolation.empty())
                    out.interpolation = Interpolation::Linear;
                else if (smp.interpolation == "STEP")
                    out.interpolation = Interpolation::Step;
                else if (smp.interpolation == "CUBICSPLINE")
                    out.interpolation = Interpolation::CubicSpline;
                else
                    return makeError(ErrorCode::Unsupported, kWhere, sfield + "/interpolation",
                                     "unknown interpolation '" + smp.interpolation + "'");

                auto in = readAccessor(g_, smp.input, TINYGLTF_TYPE_SCALAR, Want::Float,
                                       {TINYGLTF_COMPONENT_TYPE_FLOAT}, sfield + "/input");
                if (!in) return in.error();
                if (in->count == 0) return parseError(sfield + "/input", "no keys");
                out.times.resize(in->count);
                for (std::size_t k = 0; k < in->count; ++k) {
                    const double t = in->values[k];
                    if (!std::isfinite(t) || !std::isfinite(static_cast<float>(t)))
                        return parseError(sfield + "/input", "non-finite key time");
                    out.times[k] = static_cast<float>(t);
                    if (k > 0 && !(out.times[k] > out.times[k - 1]))
                        return parseError(sfield + "/input",
                                          "key times must be strictly increasing (key " + str(k) +
                                              ")");
                }
                const int type =
                    path == ChannelPath::Rotation ? TINYGLTF_TYPE_VEC4 : TINYGLTF_TYPE_VEC3;
                auto values =
                    readAccessor(g_, smp.output, type, Want::Float, {}, sfield + "/output");
                if (!values) return values.error();
                const std::size_t perKey = out.interpolation == Interpolation::CubicSpline ? 3 : 1;
                if (values->count != in->count * perKey)
                    return parseError(sfield + "/output", str(values->count) + " values for " +
                                                              str(in->count) + " keys (" +
                                                              smp.interpolation + ")");
                out.values.resize(values->values.size());
                for (std::size_t k = 0; k < values->values.size(); ++k) {
                    out.values[k] = static_cast<float>(values->values[k]);
                    if (!std::isfinite(out.values[k]))
                        return parseError(sfield + "/output", "non-finite value");
                }
                clip.duration = std::max(clip.duration, out.times.back());
                clip.channels.push_back(std::move(out));
            }
            m_.clips.push_back(std::move(clip));
        }
        return Ok{};
    }
};

/// Trims tinygltf's message to its first lines.
std::string tinygltfMessage(const std::string& err) {
    std::string s = err.substr(0, 400);
    while (!s.empty() && (s.back() == '\n' || s.back() == ' '))
        s.pop_back();
    std::replace(s.begin(), s.end(), '\n', ' ');
    return s.empty() ? std::string("not a glTF 2.0 file") : s;
}

/// parseGltf with external files from `sandbox`.
Result<ParsedGltf> parseIn(const std::vector<std::uint8_t>& bytes, Sandbox sandbox) {
    if (bytes.empty()) return parseError("", "empty input");
    if (bytes.size() > kMaxGltfBytes)
        return makeError(ErrorCode::Unsupported, kWhere, "",
                         "larger than " + str(kMaxGltfBytes) + " bytes");
    try {
        const bool binary = bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
        std::size_t length = bytes.size(), jsonOffset = 0, jsonLength = bytes.size();
        if (binary) {
            auto glb = checkGlb(bytes);
            if (!glb) return glb.error();
            length = glb->length;
            jsonOffset = glb->jsonOffset;
            jsonLength = glb->jsonLength;
        }
        const char* json = reinterpret_cast<const char*>(bytes.data()) + jsonOffset;
        if (auto s = preflight(json, jsonLength); !s) return s.error();

        Captured captured;
        tg::TinyGLTF loader;
        loader.SetImageLoader(&captureImage, &captured);
        loader.SetFsCallbacks(tg::FsCallbacks{&sandboxFileExists, &sandboxExpand, &sandboxRead,
                                              &sandboxWrite, &sandbox});
        tg::Model g;
        std::string err, warn;
        const std::string base = sandbox.memory ? std::string(kMemoryRoot) : sandbox.root.string();
        const bool ok =
            binary ? loader.LoadBinaryFromMemory(&g, &err, &warn, bytes.data(),
                                                 static_cast<unsigned int>(length), base)
                   : loader.LoadASCIIFromString(&g, &err, &warn, json,
                                                static_cast<unsigned int>(jsonLength), base);
        if (!ok) return parseError("", tinygltfMessage(err));
        return Converter(g, captured).run();
    } catch (const std::bad_alloc&) {
        return makeError(ErrorCode::Unsupported, kWhere, "", "out of memory");
    } catch (const std::exception& e) {
        return parseError("", std::string("malformed file: ") + e.what());
    }
}

} // namespace

Result<ParsedGltf> parseGltf(const std::vector<std::uint8_t>& bytes, const std::string& baseDir) {
    Sandbox sandbox;
    if (!baseDir.empty()) {
        std::error_code ec;
        sandbox.root = fs::weakly_canonical(fs::path(baseDir), ec);
        if (ec) sandbox.root.clear();
    }
    return parseIn(bytes, std::move(sandbox));
}

Status loadGltfResources(ParsedGltf& parsed) {
    for (PendingImages::Entry& e : parsed.images.entries) {
        const std::string field = "/images/" + str(e.gltfImage);
        if (e.imageIndex < 0 ||
            static_cast<std::size_t>(e.imageIndex) >= parsed.model.images.size())
            return makeError(ErrorCode::InvalidArgument, "dermis::loadGltfResources", field,
                             "image slot " + str(e.imageIndex) + " does not exist");
        auto image = decodeImage8(e.bytes);
        if (!image)
            return makeError(image.error().code == ErrorCode::Unsupported ? ErrorCode::Unsupported
                                                                          : ErrorCode::Parse,
                             "dermis::loadGltfResources", field,
                             "cannot decode (" + e.mimeType + "): " + image.error().message);
        parsed.model.images[static_cast<std::size_t>(e.imageIndex)] = std::move(*image);
    }
    parsed.images.entries.clear();
    return Ok{};
}

Result<Model> loadGltfFromFiles(const GltfFiles& files, const std::string& mainFile) {
    const char* where = "dermis::loadGltfFromFiles";
    const auto it = files.find(mainFile);
    if (it == files.end())
        return makeError(ErrorCode::NotFound, where, mainFile, "not among the given files");
    Sandbox sandbox;
    sandbox.memory = &files;
    auto parsed = parseIn(it->second, std::move(sandbox));
    if (!parsed) {
        Error e = parsed.error();
        e.message = std::string(where) + ": " + mainFile + ": " + e.message;
        return e;
    }
    if (auto s = loadGltfResources(*parsed); !s) {
        Error e = s.error();
        e.message = std::string(where) + ": " + mainFile + ": " + e.message;
        return e;
    }
    return std::move(parsed->model);
}

Result<Model> loadGltfFile(const std::string& path) {
    const char* where = "dermis::loadGltfFile";
    std::error_code ec;
    if (!fs::is_regular_file(path, ec))
        return makeError(ErrorCode::NotFound, where, path, "no such file");
    const auto size = fs::file_size(path, ec);
    if (ec) return makeError(ErrorCode::Io, where, path, "cannot read: " + ec.message());
    if (size > kMaxGltfBytes)
        return makeError(ErrorCode::Unsupported, where, path,
                         "larger than " + str(kMaxGltfBytes) + " bytes");
    std::vector<std::uint8_t> bytes(static_cast<std::size_t>(size));
    std::ifstream in(path, std::ios::binary);
    in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(size));
    if (!in) return makeError(ErrorCode::Io, where, path, "cannot read");

    const fs::path dir = fs::absolute(fs::path(path), ec).parent_path();
    auto parsed = parseGltf(bytes, dir.string());
    if (!parsed) {
        Error e = parsed.error();
        e.message = std::string(where) + ": " + path + ": " + e.message;
        return e;
    }
    if (auto s = loadGltfResources(*parsed); !s) {
        Error e = s.error();
        e.message = std::string(where) + ": " + path + ": " + e.message;
        return e;
    }
    return std::move(parsed->model);
}

} // namespace dermis
