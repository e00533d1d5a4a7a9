// glTF 2.0 loader of gltf_loader.hpp on tinygltf 2.7 (Debian's libtinygltf-dev, header only here):
// this file holds the tinygltf implementation, the checks run before tinygltf sees the bytes, the
// tinygltf callbacks (image capture, confined file access), texture downscaling and the public
// entry points (parseGltf, loadGltfResources, loadGltfFile, loadGltfFromFiles). The limits on
// declared sizes are checked in gltf_preflight.cpp, called here between tinygltf and the converter
// and before any image is decoded. Accessors are read in gltf_accessors.cpp,
// the glTF model is converted to a Model in gltf_convert.cpp; gltf_internal.hpp joins them.
//
// tinygltf parses the JSON and resolves buffers; everything then read from a buffer is validated
// (gltf_accessors.cpp: tinygltf does not bounds-check accessors). Three holes of tinygltf 2.7 are
// closed before it runs, because they crash or read out of bounds inside tinygltf itself on
// hostile input:
//   * the GLB container is checked here (tinygltf's BIN-chunk check forgets the 8-byte chunk
//     header);
//   * images stored in buffer views are bounds-checked against their buffer (tinygltf passes
//     &buffer.data[byteOffset] and byteLength to the image hook unchecked; fixed upstream by
//     tinygltf PR #512, after 2.7);
//   * JSON nesting is limited (tinygltf copies `extras` recursively and would overflow the stack).
// File access (external buffers and images of a .gltf) goes through callbacks confined to the
// model's folder: absolute URIs, "..", and symbolic links out of the folder are refused, and a
// model parsed from memory without a folder may not reference files at all.
#define TINYGLTF_IMPLEMENTATION // in this unit only; the configuration is in gltf_internal.hpp
#include "core/preview.hpp"
#include "gltf_internal.hpp"    // first: it includes <tiny_gltf.h>

#include "gltf_loader.hpp"

#include "io/image_io.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <optional>

namespace dermis {
namespace gltf_detail {

Error parseError(const std::string& field, const std::string& what) {
    return makeError(ErrorCode::Parse, kWhere, field, what);
}

std::string str(std::size_t v) {
    return std::to_string(v);
}
std::string str(int v) {
    return std::to_string(v);
}

} // namespace gltf_detail

using namespace gltf_detail;

namespace {

namespace fs = std::filesystem;

/// Deepest JSON nesting accepted (glTF itself needs about 8 levels; the rest is for extras).
constexpr int kMaxJsonDepth = 64;

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
// tinygltf callbacks: image capture (into Captured, gltf_internal.hpp) and confined file access

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

/// Trims tinygltf's message to its first lines.
std::string tinygltfMessage(const std::string& err) {
    std::string s = err.substr(0, 400);
    while (!s.empty() && (s.back() == '\n' || s.back() == ' '))
        s.pop_back();
    std::replace(s.begin(), s.end(), '\n', ' ');
    return s.empty() ? std::string("not a glTF 2.0 file") : s;
}

/// parseGltf with external files from `sandbox`.
Result<ParsedGltf> parseIn(const std::vector<std::uint8_t>& bytes, Sandbox sandbox,
                           const GltfLimits& limits) {
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
        if (auto s = checkDeclaredSizes(g, limits); !s) return s.error();
        return convertGltf(g, captured);
    } catch (const std::bad_alloc&) {
        return makeError(ErrorCode::Unsupported, kWhere, "", "out of memory");
    } catch (const std::exception& e) {
        return parseError("", std::string("malformed file: ") + e.what());
    }
}

} // namespace

Result<ParsedGltf> parseGltf(const std::vector<std::uint8_t>& bytes, const std::string& baseDir,
                             const GltfLimits& limits) {
    Sandbox sandbox;
    if (!baseDir.empty()) {
        std::error_code ec;
        sandbox.root = fs::weakly_canonical(fs::path(baseDir), ec);
        if (ec) sandbox.root.clear();
    }
    return parseIn(bytes, std::move(sandbox), limits);
}

Status loadGltfResources(ParsedGltf& parsed, const GltfLimits& limits) {
    // Every declared size first: nothing is decoded when the textures are over budget.
    std::vector<ImageSize> declared;
    if (auto s = checkDeclaredTextures(parsed.images, limits, "dermis::loadGltfResources",
                                       declared);
        !s)
        return s.error();
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
        if (image->width > limits.maxImageSide || image->height > limits.maxImageSide)
            *image = downsizeImage(*image, std::max(1, limits.maxImageSide));
        parsed.model.images[static_cast<std::size_t>(e.imageIndex)] = std::move(*image);
    }
    parsed.images.entries.clear();
    return Ok{};
}

Result<Model> loadGltfFromFiles(const GltfFiles& files, const std::string& mainFile,
                                const GltfLimits& limits) {
    const char* where = "dermis::loadGltfFromFiles";
    const auto it = files.find(mainFile);
    if (it == files.end())
        return makeError(ErrorCode::NotFound, where, mainFile, "not among the given files");
    Sandbox sandbox;
    sandbox.memory = &files;
    auto parsed = parseIn(it->second, std::move(sandbox), limits);
    if (!parsed) {
        Error e = parsed.error();
        e.message = std::string(where) + ": " + mainFile + ": " + e.message;
        return e;
    }
    if (auto s = loadGltfResources(*parsed, limits); !s) {
        Error e = s.error();
        e.message = std::string(where) + ": " + mainFile + ": " + e.message;
        return e;
    }
    return std::move(parsed->model);
}

Result<Model> loadGltfFile(const std::string& path, const GltfLimits& limits) {
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
    auto parsed = parseGltf(bytes, dir.string(), limits);
    if (!parsed) {
        Error e = parsed.error();
        e.message = std::string(where) + ": " + path + ": " + e.message;
        return e;
    }
    if (auto s = loadGltfResources(*parsed, limits); !s) {
        Error e = s.error();
        e.message = std::string(where) + ": " + path + ": " + e.message;
        return e;
    }
    return std::move(parsed->model);
}

} // namespace dermis
