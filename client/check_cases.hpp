// dermis (client) — the checks file of `dermis check`: named cases, each a scene (a document file,
// a stored scene id, or an inline document), frames (times, a pose, or a pose per time), a camera,
// a size and a view, with the comparison tolerance. JSON:
//   {"threshold": 0.1, "fraction": 0.005,            // optional, the defaults shown
//    "defaults": {"scene": "default.scene.json", "size": [128, 128]},  // merged under each case
//    "cases": [{"name": "rest", "time": 0},
//              {"name": "curl", "pose": {"animation": "elbow_curl", "time": 1.0}, "camera": {"yaw": -30}},
//              {"name": "squat", "pose": {"animation": "squat"}, "times": [0.5, 1.25]}]}
// A case's reference image is <refs>/<name>.png, or <refs>/<name>_<k>.png for each of several times.
// parseChecks throws CliError exit 2 naming the member (a JSON pointer) on a malformed file.
#pragma once

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace dermis::cli {

struct CheckFrame {
    std::string reference;  ///< file name under --refs (<name>.png or <name>_<k>.png)
    nlohmann::json request; ///< the batch frame: {"time"} and/or {"pose"}
};

struct CheckCase {
    std::string name;
    std::string sceneFile;  ///< a document file (absolute, or relative to the checks file), or
    std::string sceneId;    ///< a stored scene, or
    nlohmann::json sceneDoc;///< an inline document (null when not)
    nlohmann::json size, camera; ///< [w, h] and {yaw, pitch, distance} (null = the scene's)
    std::string view = "shaded";
    double threshold = 0.1, fraction = 0.005;
    std::vector<CheckFrame> frames;
};

/// The cases of checks file `path`.
std::vector<CheckCase> parseChecks(const std::string& path);

} // namespace dermis::cli
