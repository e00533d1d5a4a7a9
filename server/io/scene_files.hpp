// Dermis io shell — scene documents on disk: reads the JSON, resolves paths relative to the
// document and `builtin:` names, loads the model, pattern images and static base map.
//
// Built-in content lives in the pattern library folder (patterns/manifest.json) and the built-in
// model folder; both are found through dermisDataDir().
#pragma once

#include "core/bake.hpp"
#include "core/model.hpp"
#include "core/result.hpp"
#include "core/scene.hpp"

#include <memory>
#include <optional>
#include <string>

namespace dermis {

/// Folder holding `patterns/` (and built-in models): $DERMIS_DATA_DIR if set, else the source
/// tree the binary was built from.
std::string dermisDataDir();

/// The built-in pattern manifest (patterns/manifest.json). A missing manifest yields an empty
/// library (custom patterns still work); a corrupt one is an error.
Result<PatternManifest> loadBuiltinManifest();

/// Resolves a model reference of a scene: "builtin:<name>" → <data>/patterns/../models/<name>.glb,
/// otherwise a path relative to `baseDir`.
std::string resolveModelPath(const std::string& ref, const std::string& baseDir);

struct LoadedScene {
    Scene scene;
    std::string baseDir;            ///< folder of the document
    Model model;
    PatternImages images;           ///< every pattern a placement uses, by id
    std::shared_ptr<const PatternImage> base; ///< heightmap.base, if any
};

/// Reads and validates a scene file and everything it references.
Result<LoadedScene> loadSceneFile(const std::string& path);

} // namespace dermis
