// dermis-charactergen — a tiny CPU rasterizer for check images (not part of the product).
//
// Orthographic, z-buffered, Lambert-shaded views of a triangle mesh, optionally with per-vertex
// colours and a wireframe overlay, and flat drawings of a UV layout. Written as 8-bit RGB PNG
// through OpenImageIO.
#pragma once

#include <glm/glm.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace dermis::chargen {

struct RgbImage {
    int width = 0, height = 0;
    std::vector<std::uint8_t> rgb; ///< width·height·3 bytes, row 0 at the top
    RgbImage(int w, int h, glm::vec3 background);
    void set(int x, int y, glm::vec3 c);
};

struct ViewSpec {
    int x0 = 0, y0 = 0, width = 0, height = 0; ///< viewport in the image
    float yawDeg = 0.0f;           ///< 0: looking at the character's front (from +Z); 90: its left
    float pitchDeg = 0.0f;         ///< positive: looking down
    glm::vec3 centre{0, 0.88f, 0}; ///< world point at the viewport centre
    float pixelsPerMetre = 250.0f;
    bool wireframe = false;
};

/// Draws a mesh. `colors` (one per vertex) may be empty (skin tone).
void renderMesh(RgbImage& img, const ViewSpec& view, const std::vector<glm::vec3>& positions,
                const std::vector<glm::vec3>& normals, const std::vector<glm::uvec3>& tris,
                const std::vector<glm::vec3>& colors);

/// Draws UV triangles (u right, v down) into a square viewport, filled with per-triangle
/// colours, with edges.
void renderUv(RgbImage& img, int x0, int y0, int size, const std::vector<glm::vec2>& uvs,
              const std::vector<glm::uvec3>& tris, const std::vector<glm::vec3>& triColors);

/// Writes an 8-bit RGB PNG. Returns false (message on stderr) on failure.
bool writePng(const std::string& path, const RgbImage& img);

} // namespace dermis::chargen
