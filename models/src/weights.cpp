// Skin weights of the default character (see weights.hpp).
#include "weights.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

namespace dermis::chargen {
namespace {

float smoothstep(float e0, float e1, float x) {
    const float t = std::clamp((x - e0) / (e1 - e0), 0.0f, 1.0f);
    return t * t * (3.0f - 2.0f * t);
}

constexpr float kOwnershipSigma = 0.015f; // metres
constexpr int kSmoothingRounds = 3;

} // namespace

std::vector<float> chainWeights(const Chain& chain, const glm::vec3& p) {
    const std::size_t n = chain.bones.size();
    std::vector<float> w(n, 0.0f);
    float carried = 1.0f; // share of the bones from k on
    for (std::size_t k = 0; k + 1 < n; ++k) {
        const glm::vec3 pj = chain.points[k + 1];
        glm::vec3 normal = chain.junctionNormal.size() > k ? chain.junctionNormal[k] : glm::vec3(0);
        if (glm::dot(normal, normal) == 0.0f) {
            const glm::vec3 d0 = glm::normalize(pj - chain.points[k]);
            const glm::vec3 d1 = glm::normalize(chain.points[k + 2] - pj);
            normal = glm::normalize(d0 + d1);
        }
        const float h = chain.halfWidth[k];
        const float next = smoothstep(-h, h, glm::dot(p - pj, normal));
        w[k] = carried * (1.0f - next);
        carried *= next;
    }
    w[n - 1] = carried;
    return w;
}

SkinWeights computeWeights(const TriMesh& mesh, const Body& body, const Skeleton& skeleton) {
    const std::size_t nv = mesh.positions.size();
    const std::size_t nj = skeleton.joints.size();
    const auto& groups = body.groups();
    const auto& chains = body.chains();
    std::vector<float> w(nv * nj, 0.0f);
    std::vector<float> d, chainDist(chains.size());
    for (std::size_t v = 0; v < nv; ++v) {
        const glm::vec3 p = mesh.positions[v];
        body.groupDistances(p, d);
        std::fill(chainDist.begin(), chainDist.end(), 1e9f);
        for (std::size_t g = 0; g < groups.size(); ++g) {
            auto& cd = chainDist[static_cast<std::size_t>(groups[g].chain)];
            cd = std::min(cd, d[g]);
        }
        const float dmin = *std::min_element(chainDist.begin(), chainDist.end());
        float osum = 0.0f;
        std::vector<float> own(chains.size());
        for (std::size_t c = 0; c < chains.size(); ++c) {
            own[c] = std::exp(-(chainDist[c] - dmin) / kOwnershipSigma);
            if (own[c] < 1e-3f) own[c] = 0.0f;
            osum += own[c];
        }
        for (std::size_t c = 0; c < chains.size(); ++c) {
            if (own[c] == 0.0f) continue;
            const std::vector<float> cw = chainWeights(chains[c], p);
            for (std::size_t b = 0; b < cw.size(); ++b)
                w[v * nj + static_cast<std::size_t>(chains[c].bones[b])] += own[c] / osum * cw[b];
        }
    }

    // One-ring smoothing (Jacobi, half step) softens the ownership seams.
    std::vector<std::vector<std::uint32_t>> ring(nv);
    for (const auto& t : mesh.tris)
        for (int c = 0; c < 3; ++c) {
            ring[t[c]].push_back(t[(c + 1) % 3]);
            ring[t[c]].push_back(t[(c + 2) % 3]);
        }
    for (auto& r : ring) {
        std::sort(r.begin(), r.end());
        r.erase(std::unique(r.begin(), r.end()), r.end());
    }
    for (int round = 0; round < kSmoothingRounds; ++round) {
        std::vector<float> next(w.size());
        for (std::size_t v = 0; v < nv; ++v) {
            const float inv = 1.0f / static_cast<float>(ring[v].size());
            for (std::size_t j = 0; j < nj; ++j) {
                float avg = 0.0f;
                for (std::uint32_t u : ring[v])
                    avg += w[u * nj + j];
                next[v * nj + j] = 0.5f * w[v * nj + j] + 0.5f * avg * inv;
            }
        }
        w.swap(next);
    }

    SkinWeights out;
    out.joints.resize(nv);
    out.weights.resize(nv);
    std::vector<std::size_t> order(nj);
    for (std::size_t v = 0; v < nv; ++v) {
        std::iota(order.begin(), order.end(), std::size_t(0));
        // Largest first; ties by joint index (deterministic).
        std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
            const float wa = w[v * nj + a], wb = w[v * nj + b];
            return wa != wb ? wa > wb : a < b;
        });
        std::array<float, 4> top{};
        float sum = 0.0f;
        for (int k = 0; k < 4; ++k) {
            top[static_cast<std::size_t>(k)] = w[v * nj + order[static_cast<std::size_t>(k)]];
            // Influences below 1% are dropped: they only add noise to four-weight budgets.
            if (top[static_cast<std::size_t>(k)] < 0.01f) top[static_cast<std::size_t>(k)] = 0.0f;
            sum += top[static_cast<std::size_t>(k)];
        }
        glm::u16vec4 ji(0);
        glm::vec4 wi(0.0f);
        for (int k = 0; k < 4; ++k) {
            if (top[static_cast<std::size_t>(k)] == 0.0f) continue;
            ji[k] = static_cast<std::uint16_t>(order[static_cast<std::size_t>(k)]);
            wi[k] = top[static_cast<std::size_t>(k)] / sum;
        }
        // Make the float sum exact: the largest weight takes the rounding remainder.
        wi[0] = 1.0f - (wi[1] + wi[2] + wi[3]);
        out.joints[v] = ji;
        out.weights[v] = wi;
    }
    return out;
}

} // namespace dermis::chargen
