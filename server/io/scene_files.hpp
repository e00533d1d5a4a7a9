// Dermis io shell — scene documents on disk: reads the JSON, resolves paths relative to the
// document and `builtin:` names, loads the model, pattern images and static base map.
//
// Built-in content (the pattern library, built-in characters, the editor) lives in one content
// folder, dermisContentDir(): code and content are apart from the server's data folder (uploads
// and scenes, `serve --data`), which this file knows nothing of.
#pragma once

#include "core/bake.hpp"
#include "core/model.hpp"
#include "core/result.hpp"
#include "core/scene.hpp"

#include <memory>
#include <optional>
#include <string>

namespace dermis {

/// The built-in content folder: `patterns/` (library + manifest.json), `models/` (built-in
/// characters, the default pattern set) and `web/` (the editor). $DERMIS_CONTENT_DIR if set, else
/// the source tree the binary was built from. Never written to.
std::string dermisContentDir();

/// The built-in pattern manifest (<content>/patterns/manifest.json). A missing manifest yields an
/// empty library (custom patterns still work); a corrupt one is an error.
Result<PatternManifest> loadBuiltinManifest(const std::string& contentDir = dermisContentDir());

/// Resolves a model reference of a scene: "builtin:<name>" → <content>/models/<name>.glb,
/// otherwise a path relative to `baseDir` (absolute paths stay as they are).
std::string resolveModelPath(const std::string& ref, const std::string& baseDir,
                             const std::string& contentDir = dermisContentDir());

struct LoadedScene {
    Scene scene;
    std::string baseDir;            ///< folder of the document
    Model model;
    PatternImages images;           ///< every pattern a placement uses, by id
    std::shared_ptr<const PatternImage> base; ///< heightmap.base, if any
};

/// Reads and validates a scene file and everything it references (built-in names from
/// `contentDir`).
Result<LoadedScene> loadSceneFile(const std::string& path,
                                  const std::string& contentDir = dermisContentDir());

} // namespace dermis
