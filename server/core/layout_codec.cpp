// Dermis core — texture layouts as bytes (layout_codec.hpp).
#include "layout_codec.hpp"

#include <cmath>
#include <cstring>

namespace dermis {
namespace {

constexpr char kMagic[4] = {'D', 'M', 'L', 'Y'};
constexpr std::uint32_t kVersion = 1;

void putU32(std::vector<std::uint8_t>& out, std::uint32_t v) {
    for (int k = 0; k < 4; ++k) out.push_back(static_cast<std::uint8_t>(v >> (8 * k)));
}

void putF32(std::vector<std::uint8_t>& out, float f) {
    std::uint32_t v;
    std::memcpy(&v, &f, 4);
    putU32(out, v);
}

struct Reader {
    const std::vector<std::uint8_t>& bytes;
    std::size_t at = 0;
    bool ok = true;

    std::uint32_t u32() {
        if (bytes.size() - at < 4 || at > bytes.size()) {
            ok = false;
            return 0;
        }
        std::uint32_t v = 0;
        for (int k = 0; k < 4; ++k) v |= std::uint32_t(bytes[at + k]) << (8 * k);
        at += 4;
        return v;
    }
    float f32() {
        const std::uint32_t v = u32();
        float f;
        std::memcpy(&f, &v, 4);
        return f;
    }
    /// Whether `count` items of `size` bytes each can still be read.
    bool has(std::uint64_t count, std::uint64_t size) const {
        return ok && count * size <= bytes.size() - at;
    }
};

struct Fnv2 {
    std::uint64_t a = 0xcbf29ce484222325ull, b = 0x84222325cbf29ce4ull;
    void add(const void* data, std::size_t n) {
        const auto* p = static_cast<const std::uint8_t*>(data);
        for (std::size_t i = 0; i < n; ++i) {
            a = (a ^ p[i]) * 0x100000001b3ull;
            b = (b ^ p[i] ^ 0x5a) * 0x100000001b3ull;
        }
    }
    template <class T> void addVector(const std::vector<T>& v) {
        const std::uint64_t n = v.size();
        add(&n, sizeof n);
        if (!v.empty()) add(v.data(), v.size() * sizeof(T));
    }
};

} // namespace

std::vector<std::uint8_t> encodeTextureLayout(const TextureLayout& layout) {
    std::vector<std::uint8_t> out(kMagic, kMagic + 4);
    putU32(out, kVersion);
    putU32(out, static_cast<std::uint32_t>(layout.kind.size()));
    out.insert(out.end(), layout.kind.begin(), layout.kind.end());
    putU32(out, static_cast<std::uint32_t>(layout.parts.size()));
    for (const PartLayout& p : layout.parts) {
        putU32(out, static_cast<std::uint32_t>(p.source.size()));
        for (std::uint32_t s : p.source) putU32(out, s);
        for (std::size_t v = 0; v < p.source.size(); ++v) {
            const glm::vec2 uv = v < p.uvs.size() ? p.uvs[v] : glm::vec2(0.0f);
            putF32(out, uv.x);
            putF32(out, uv.y);
        }
        putU32(out, static_cast<std::uint32_t>(p.indices.size()));
        for (std::uint32_t i : p.indices) putU32(out, i);
    }
    return out;
}

Result<TextureLayout> decodeTextureLayout(const std::vector<std::uint8_t>& bytes, const Model& model) {
    const char* where = "dermis::decodeTextureLayout";
    auto bad = [&](const std::string& why) { return makeError(ErrorCode::Parse, where, "", why); };
    if (bytes.size() < 8 || std::memcmp(bytes.data(), kMagic, 4) != 0) return bad("not a layout file");
    Reader r{bytes, 4};
    if (r.u32() != kVersion) return bad("layout file version is not 1");
    const std::uint32_t kindLength = r.u32();
    if (!r.has(kindLength, 1) || kindLength > 64) return bad("bad kind at byte 8");
    TextureLayout layout;
    layout.kind.assign(bytes.begin() + static_cast<long>(r.at), bytes.begin() + static_cast<long>(r.at + kindLength));
    r.at += kindLength;
    const std::uint32_t parts = r.u32();
    if (!r.ok || parts != model.parts.size())
        return bad("the layout has " + std::to_string(parts) + " parts, the model " +
                   std::to_string(model.parts.size()));
    layout.parts.resize(parts);
    for (std::uint32_t k = 0; k < parts; ++k) {
        const std::string part = "part " + std::to_string(k);
        const MeshPart& mp = model.parts[k];
        PartLayout& p = layout.parts[k];
        const std::uint32_t nv = r.u32();
        if (!r.has(nv, 12)) return bad(part + ": truncated vertices");
        p.source.resize(nv);
        p.uvs.resize(nv);
        for (std::uint32_t v = 0; v < nv; ++v) {
            p.source[v] = r.u32();
            if (p.source[v] >= mp.positions.size()) return bad(part + ": vertex source out of range");
        }
        for (std::uint32_t v = 0; v < nv; ++v) {
            p.uvs[v].x = r.f32();
            p.uvs[v].y = r.f32();
            if (!std::isfinite(p.uvs[v].x) || !std::isfinite(p.uvs[v].y)) return bad(part + ": UV not finite");
        }
        const std::uint32_t ni = r.u32();
        if (!r.has(ni, 4)) return bad(part + ": truncated indices");
        if (ni != 0 && ni != mp.indices.size())
            return bad(part + ": " + std::to_string(ni) + " indices where the model has " +
                       std::to_string(mp.indices.size()));
        p.indices.resize(ni);
        for (std::uint32_t i = 0; i < ni; ++i) {
            p.indices[i] = r.u32();
            if (p.indices[i] >= nv) return bad(part + ": index out of range");
        }
    }
    if (!r.ok || r.at != bytes.size()) return bad("trailing or missing bytes");
    return layout;
}

std::string layoutContentKey(const Model& model, std::string_view salt) {
    Fnv2 h;
    h.add(salt.data(), salt.size());
    const std::uint64_t parts = model.parts.size();
    h.add(&parts, sizeof parts);
    for (const MeshPart& p : model.parts) {
        h.addVector(p.positions);
        h.addVector(p.normals);
        h.addVector(p.uvs);
        h.addVector(p.indices);
    }
    static const char* hex = "0123456789abcdef";
    std::string out;
    for (std::uint64_t v : {h.a, h.b})
        for (int k = 15; k >= 0; --k) out += hex[(v >> (4 * k)) & 15];
    return out;
}

} // namespace dermis
