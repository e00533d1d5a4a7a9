// dermis (client) — content addresses for stateless batches (SPEC §7): a scene file names its
// model, pattern images and environment as files of this machine; the batch names them by content
// address ("sha256:<hex>" of the bytes) so that any replica behind a load balancer can serve it. A
// replica that lacks one answers 409 missing_content with the addresses, and the batch is sent
// again as multipart/form-data with those files' bytes (batch.cpp).
#pragma once

#include <nlohmann/json.hpp>

#include <map>
#include <string>
#include <vector>

namespace dermis::cli {

/// The local files a batch's document names, by content address.
struct ContentFiles {
    std::map<std::string, std::string> paths; ///< "sha256:<64 hex>" → file path
    bool empty() const { return paths.empty(); }
};

/// Rewrites `scene`, a document read from `sceneFile`, so that its model, the values of its
/// pattern map, its height map's base and its render's environment (.hdr / .exr) name their file
/// by content address when they name an existing file (relative to the scene file's folder, as
/// `dermis-server render --scene` reads them); returns those files by address. Strings that are no file (ids, builtin:, sha256:) are
/// left alone for the server to resolve. Reads and hashes each file once. Fails (CliError exit 2,
/// field the document member) on an unreadable file, and on a .gltf whose buffers or images are
/// files of their own (only a .glb or a self-contained .gltf can be sent by content).
ContentFiles addressContent(nlohmann::json& scene, const std::string& sceneFile);

/// The multipart/form-data body of a batch sent with content: part "request" (the JSON batch),
/// then one part per address in `addresses`, named by it, with its file's bytes. Fails (CliError
/// exit 1) when an address is not among `files` (the server asks for content this client did not
/// name by file), exit 2 when a file cannot be read any more.
std::string contentBody(const nlohmann::json& request, const std::vector<std::string>& addresses,
                        const ContentFiles& files, const std::string& boundary);

} // namespace dermis::cli
