// Dermis core — data derived from one immutable model, built once and shared by every request that
// reads it: the UV index (UvLookup: lint, pick by UV, mirror), the rest-pose skinning (RestSkin:
// mirror, lint's mirror pairs, the symmetry plane), the rest pose's symmetry plane (mirror, lint),
// the UV diagnosis (GET /models/{id}, lint's uv_overlap and no_influence, uv_layout auto), the
// joints' angle ranges over the clips (the picks' driver suggestion), the model's own UVs as a
// height-map layout and the rest-surface maps of layouts (SPEC §8; a small cache). The service
// keeps one per model entry, and model ids are content addresses: the diagnosis is cached by
// content. Each piece
// is built lazily, on its first use, at most once (std::call_once): a route pays only for what it
// reads, and concurrent first uses wait for one build instead of each making its own.
//
//   ModelDerived      the derived data of one model; holds that model (shared), so the UvLookup's
//                     pointer into it stays valid for as long as anyone holds the ModelDerived.
//   ModelDerivedSlot  where a model's ModelDerived lives next to the model (the service's model
//                     entry): made on the first get(), then the same object for that model; freed
//                     with the slot (a deleted model's entry), once no request holds it.
//
// Pure (no GL, no I/O); thread-safe. Core mirrorPlacement and lintScene take these pieces through
// their overloads (mirror.hpp, lint.hpp). Not cached: anything that depends on a scene or a pose
// (lint's clip sampling against the placements' ranges, mirror's nearest-point search).
#pragma once

#include "body_map.hpp"
#include "mirror.hpp"
#include "model.hpp"
#include "motion.hpp"
#include "propose.hpp"
#include "pick.hpp"
#include "uv_diagnosis.hpp"
#include "texture_layout.hpp"
#include "uv_lookup.hpp"

#include <array>
#include <atomic>
#include <memory>
#include <mutex>
#include <utility>
#include <vector>

namespace dermis {

class ModelDerived {
public:
    /// Nothing is computed yet. A null `model` stands for an empty one (no triangles, no joints:
    /// an empty lookup, the plane x = 0, no suggestion); nothing here throws but std::bad_alloc.
    explicit ModelDerived(std::shared_ptr<const Model> model);
    ModelDerived(const ModelDerived&) = delete;
    ModelDerived& operator=(const ModelDerived&) = delete;

    const Model& model() const { return *model_; }
    const std::shared_ptr<const Model>& modelPtr() const { return model_; }

    /// The model's UV index (UvLookup(model()), default cells), built on the first call. The
    /// reference lives as long as this object. A build that throws (std::bad_alloc) is retried
    /// by the next call.
    const UvLookup& uvLookup() const;
    /// restSkin(model()) (core mirror.hpp: rest world matrices, rest-skinned parts, their
    /// bounds), computed on the first call. Same lifetime and retry rule as uvLookup().
    const RestSkin& restSkin() const;
    /// symmetryPlane(model()), bit for bit, computed on the first call (O(vertices · 450)) from
    /// restSkin() (which it builds if not yet built).
    const SymmetryPlane& symmetryPlane() const;

    /// diagnoseUvs(model(), restSkin(), symmetryPlane()) at the default resolution (1024²),
    /// computed on the first call (building the rest skin and plane if not yet built). Same
    /// lifetime and retry rule as uvLookup().
    const UvDiagnosis& uvDiagnosis() const;

    /// core suggestDriver(model(), joints), bit for bit, with the clips sampled once per model:
    /// the angle range of every skin joint about x, y and z over all clips at 15 fps (what that
    /// function samples per call) is computed on the first call that needs it. Joints that are
    /// not skin joints, an empty list and a model without clips go to suggestDriver itself.
    SuggestedDriver suggestDriver(const std::vector<std::pair<int, float>>& joints) const;

    /// mapBody(model(), restSkin(), symmetryPlane()) (what each joint is), on the first call.
    const BodyMap& bodyMap() const;
    /// analyzeMotion(model(), restSkin(), bodyMap()) (the range-of-motion analysis), on the
    /// first call.
    const MotionAnalysis& motion() const;
    /// proposePatterns(…) of this model (SPEC §8 proposals; bind space, so the same for every
    /// layout), on the first call.
    const std::vector<Proposal>& proposals() const;
    int proposalBuilds() const { return proposalBuilds_.load(); }

    /// modelTextureLayout(model()) (SPEC §8: the model's own UVs as a height-map layout), built
    /// on the first call; the same object for the lifetime of this one (a stable key for the
    /// renderer's per-layout vertex arrays and for restSurface below).
    const std::shared_ptr<const TextureLayout>& modelLayout() const;
    /// bakeRestSurface(model(), *layout, width, height), cached by (layout object, size): the
    /// kRestCacheEntries most recently used maps are kept (each is ~25 bytes per texel). Built
    /// outside the cache's lock; two first uses at once may both bake (one result is kept).
    /// `layout` must be a layout of model(); null = modelLayout().
    std::shared_ptr<const RestSurfaceMap> restSurface(const std::shared_ptr<const TextureLayout>& layout,
                                                      int width, int height) const;
    static constexpr std::size_t kRestCacheEntries = 2;

    /// The derived data of model() seen through `layout` (core modelThroughLayout): its UV index,
    /// UV diagnosis, rest skin, … in that layout's texture space, for the tools that work there
    /// (pick by UV, focus, mirror, lint) when the layout in use is not the model's own. Made on
    /// the first call per layout object and kept while this object lives (the service asks for
    /// one: the generated layout). `layout` must be a layout of model() and not null.
    std::shared_ptr<const ModelDerived> throughLayout(const std::shared_ptr<const TextureLayout>& layout) const;

    /// How many times each piece was built: 0 before its first use, 1 after (for tests).
    int uvLookupBuilds() const { return lookupBuilds_.load(); }
    int restSkinBuilds() const { return restBuilds_.load(); }
    int symmetryPlaneBuilds() const { return planeBuilds_.load(); }
    int clipRangeBuilds() const { return rangesBuilds_.load(); }
    int uvDiagnosisBuilds() const { return diagnosisBuilds_.load(); }
    int restSurfaceBuilds() const { return restSurfaceBuilds_.load(); }

private:
    std::shared_ptr<const Model> model_;
    mutable std::once_flag lookupOnce_, restOnce_, planeOnce_;
    mutable std::unique_ptr<const UvLookup> lookup_;
    mutable RestSkin rest_;
    mutable SymmetryPlane plane_;
    mutable std::once_flag diagnosisOnce_;
    mutable UvDiagnosis diagnosis_;
    mutable std::once_flag rangesOnce_;
    mutable std::vector<std::array<AngleRange, 3>> ranges_; ///< by node; x, y, z
    mutable std::vector<bool> ranged_;                      ///< by node: a skin joint, in ranges_
    mutable std::atomic<int> lookupBuilds_{0}, restBuilds_{0}, planeBuilds_{0}, rangesBuilds_{0},
        diagnosisBuilds_{0};
    mutable std::once_flag bodyOnce_, motionOnce_, proposalsOnce_;
    mutable BodyMap body_;
    mutable MotionAnalysis motion_;
    mutable std::vector<Proposal> proposals_;
    mutable std::atomic<int> proposalBuilds_{0};
    mutable std::once_flag layoutOnce_;
    mutable std::shared_ptr<const TextureLayout> layout_;
    struct RestEntry {
        std::weak_ptr<const TextureLayout> layout;
        int width = 0, height = 0;
        std::shared_ptr<const RestSurfaceMap> map;
    };
    mutable std::mutex restMutex_;
    mutable std::vector<RestEntry> restCache_; ///< most recently used first
    mutable std::atomic<int> restSurfaceBuilds_{0};
    mutable std::mutex throughMutex_;
    mutable std::vector<std::pair<std::shared_ptr<const TextureLayout>, std::shared_ptr<const ModelDerived>>> through_;
};

class ModelDerivedSlot {
public:
    /// The ModelDerived of `model`: the one made before for this same model (pointer identity),
    /// else a new one (nothing computed yet: that happens outside this slot's lock, on use). A
    /// slot asked for a different model than before replaces its object (holders of the old one
    /// keep it; a null model gets a new, empty one each time).
    std::shared_ptr<const ModelDerived> get(const std::shared_ptr<const Model>& model);
    /// The object made so far (null before the first get), without making one.
    std::shared_ptr<const ModelDerived> peek() const;

private:
    mutable std::mutex mutex_;
    std::shared_ptr<const ModelDerived> derived_;
};

} // namespace dermis
