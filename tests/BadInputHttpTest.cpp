// BadInputHttpTest — the errors table, end to end on one server (HttpTestFixture.hpp: a real
// dermis::Service + dermis::Api on 127.0.0.1, a GL context on $DERMIS_TEST_GL, cpp-httplib clients
// over loopback). It checks:
//   * a table of bad inputs (malformed JSON, wrong types, non-finite and out-of-bounds numbers, unknown ids, path
//     tricks, bad sizes and formats, corrupt and oversized uploads, wrong content types, sign-in
//     bodies, conflicts, limits): each answers {"error": {"code", "message", "field"}} with the
//     right status and the server stays healthy after each; none of them changes what it refers to.
#include "HttpTestFixture.hpp"

using namespace dermis;
using namespace dermis::test;
using namespace dermis::test::http;

namespace {

/// One server (no token).
class BadInputHttpTest : public SharedServerTest {};

// ================================================================================================
// Bad input: one table, each case answered with the JSON error and the right status
// ================================================================================================

struct BadCase {
    std::string name, method, path, contentType, body;
    std::vector<int> statuses; ///< any of these
    std::string field;         ///< expected "field" when not empty
};

std::string nested(std::size_t depth, bool closed) {
    std::string s(depth, '[');
    if (closed) s += std::string(depth, ']');
    return s;
}

TEST_F(BadInputHttpTest, BadInputGetsAJsonErrorWithTheRightStatus) {
    Http h = http();
    // The state the cases refer to: a scene {S} with placements "elbow" and "knee", an uploaded
    // model {M} used by scene {SM}, an uploaded pattern {P} used by scene {SP}.
    json sceneDoc = smallScene();
    sceneDoc["placements"].push_back(placementOf("crease", "knee"));
    const std::string S = createScene(sceneDoc);
    const std::string M = uploadModel(kCesiumMan);
    const std::string SM = createScene(
        {{"format", "dermis.scene/1"}, {"model", M}, {"heightmap", {{"size", {256, 256}}}}});
    Reply pu = h.upload("/patterns?name=bad-input", domePng(), "image/png");
    ASSERT_EQ(pu.status, 201) << pu;
    const std::string P = pu.js()["id"];
    json usingP = smallScene();
    usingP["placements"] = {placementOf(P, "x")};
    const std::string SP = createScene(usingP);
    ASSERT_FALSE(S.empty() || M.empty() || SM.empty() || SP.empty());

    const std::vector<std::uint8_t> cesium = readBytes(kCesiumMan);
    std::mt19937 rng(1234);
    std::string randomBytes(4096, '\0');
    for (char& c : randomBytes)
        c = static_cast<char>(rng() & 0xff);
    std::string glbGarbage =
        "glTF" + std::string("\x02\x00\x00\x00\x00\x10\x00\x00", 8) + randomBytes;
    std::string truncatedGlb(cesium.begin(), cesium.begin() + 100);
    std::string halfGlb(cesium.begin(), cesium.begin() + static_cast<long>(cesium.size() / 2));
    const std::string gltfJson =
        R"({"asset": {"version": "2.0"}, "buffers": [{"uri": "/etc/passwd", "byteLength": 10}]})";
    std::string png = str(domePng());
    std::string corruptPng = png.substr(0, 8) + randomBytes;
    std::string truncatedPng = png.substr(0, png.size() / 2);
    std::string widePng = str(domePng(5000, 1)); // over maxImageSide (4096)
    std::string oversized(kMaxUpload + 1024, 'x');
    std::copy_n("glTF", 4, oversized.begin());

    // Scene documents with one thing wrong (built from the small scene).
    auto doc = [&](auto edit) {
        json d = smallScene();
        edit(d);
        return d.dump();
    };
    auto withPlacementField = [&](const char* key, json value) {
        return doc([&](json& d) { d["placements"][0][key] = value; });
    };
    auto replaceInDoc = [&](const std::string& from, const std::string& to) {
        std::string s = smallScene().dump();
        s.replace(s.find(from), from.size(), to);
        return s;
    };
    auto withModel = [&](const std::string& model) {
        return doc([&](json& d) { d["model"] = model; });
    };
    json manyPlacements = smallScene();
    manyPlacements["placements"] = json::array();
    for (std::size_t i = 0; i <= kMaxPlacements; ++i)
        manyPlacements["placements"].push_back(placementOf("crease", "p" + std::to_string(i)));
    auto batch = [&](json frames, json format = "png") {
        return json{
            {"scene", smallScene()}, {"frames", std::move(frames)}, {"format", std::move(format)}}
            .dump();
    };
    json tenThousand = json::array();
    for (int i = 0; i < 10000; ++i)
        tenThousand.push_back({{"time", 0}});

    const std::string J = "application/json";
    const std::string GLB = "model/gltf-binary";
    const std::string scene = "/scenes/" + S;
    // clang-format off
    const std::vector<BadCase> cases = {
        // --- malformed JSON → 400
        {"truncated JSON", "POST", "/scenes", J, R"({"model": "builtin:default", "placements": [)", {400}, "body"},
        {"trailing garbage", "POST", "/scenes", J, R"({"model": "builtin:default"} xyz)", {400}, "body"},
        {"empty body", "POST", "/scenes", J, "", {400}, "body"},
        {"BOM only", "POST", "/scenes", J, "\xEF\xBB\xBF", {400}, "body"},
        {"10000 unclosed [", "POST", "/scenes", J, nested(10000, false), {400}, "body"},
        {"NaN literal", "POST", "/scenes", J, replaceInDoc("\"theta_min\"", "\"h\": NaN, \"theta_min\""), {400}, "body"},
        {"Infinity literal", "POST", "/scenes", J, R"({"model": "builtin:default", "render": {"camera": {"yaw": Infinity}}})", {400}, "body"},
        {"-Infinity literal", "PUT", scene, J, R"({"model": "builtin:default", "pose": {"time": -Infinity}})", {400}, "body"},
        {"single quotes", "POST", "/scenes", J, "{'model': 'builtin:default'}", {400}, "body"},
        {"comment", "POST", "/scenes", J, R"({"model": "builtin:default" /* hi */})", {400}, "body"},
        {"invalid UTF-8", "POST", "/scenes", J, "{\"model\": \"\xff\xfe\"}", {400}, "body"},
        {"truncated PUT", "PUT", scene, J, R"({"model": )", {400}, "body"},
        {"truncated placement", "POST", scene + "/placements", J, R"({"pattern": "crease", )", {400}, "body"},
        {"truncated pose patch", "PATCH", scene + "/pose", J, R"({"time": 0.5)", {400}, "body"},
        {"truncated placement patch", "PATCH", scene + "/placements/elbow", J, "{\"h\": ", {400}, "body"},
        {"truncated reorder", "PUT", scene + "/placements", J, R"(["elbow", )", {400}, "body"},
        {"truncated batch", "POST", "/render", J, R"({"scene": {)", {400}, "body"},
        {"deeply nested valid JSON", "POST", "/scenes", J, nested(100000, true), {400}, "body"},
        {"deeply nested in a field", "POST", "/scenes", J, "{\"model\": \"builtin:default\", \"x\": " + nested(100000, true) + "}", {400}, "body"},
        // --- valid JSON of the wrong shape or type → 422
        {"body is an array", "POST", "/scenes", J, "[]", {422}, ""},
        {"body is a string", "POST", "/scenes", J, "\"scene\"", {422}, ""},
        {"placements: 5", "POST", "/scenes", J, doc([](json& d) { d["placements"] = 5; }), {422}, "/placements"},
        {"center: \"x\"", "POST", "/scenes", J, withPlacementField("center", "x"), {422}, "/placements/0/center"},
        {"h: \"1\"", "POST", "/scenes", J, withPlacementField("h", "1"), {422}, "/placements/0/h"},
        {"heightmap size a string", "POST", "/scenes", J, doc([](json& d) { d["heightmap"]["size"] = "big"; }), {422}, "/heightmap/size"},
        {"default_patterns a string", "POST", "/scenes", J, R"({"default_patterns": "yes"})", {422}, "/default_patterns"},
        {"default_patterns on another model", "POST", "/scenes", J, "{\"default_patterns\": true, \"model\": \"" + M + "\"}", {422}, "/default_patterns"},
        {"default_patterns with a numeric model", "POST", "/scenes", J, R"({"default_patterns": true, "model": 5})", {422}, "/model"},
        {"default_patterns with a null model", "POST", "/scenes", J, R"({"default_patterns": true, "model": null})", {422}, "/model"},
        {"frame exposure over 64", "GET", scene + "/frame?exposure=100&width=64&height=64", "", "", {422}, "exposure"},
        {"frame-diff against an unknown revision", "GET", scene + "/frame-diff?against=999&width=64&height=64", "", "", {404}, "against"},
        {"revert with another member", "POST", scene + "/revert", J, R"({"revision": 1, "note": "x"})", {422}, "/note"},
        {"multipart .gltf that is no JSON", "POST", "/models", "multipart/form-data; boundary=dermisXYZ",
         "--dermisXYZ\r\nContent-Disposition: form-data; name=\"gltf\"; filename=\"s.gltf\"\r\nContent-Type: model/gltf+json\r\n\r\n{\r\n--dermisXYZ--\r\n",
         {400}, "files/s.gltf"},
        {"unsupported format version", "POST", "/scenes", J, doc([](json& d) { d["format"] = "dermis.scene/2"; }), {422}, "/format"},
        {"3-element rotation", "PUT", scene + "/pose", J, R"({"joints": {"head": {"rotation": [0, 0, 1]}}})", {422}, "/pose/joints/head/rotation"},
        {"pose is an array", "PUT", scene + "/pose", J, "[1, 2]", {422}, "/pose"},
        {"pose patch joints: 5", "PATCH", scene + "/pose", J, R"({"joints": 5})", {422}, "/pose/joints"},
        {"placement is a number", "POST", scene + "/placements", J, "42", {422}, ""},
        {"duplicate placement id", "POST", scene + "/placements", J, placementOf("crease", "elbow").dump(), {422}, "/placements/2/id"},
        {"render msaa 3 in the document", "PUT", scene, J, doc([](json& d) { d["render"]["msaa"] = 3; }), {422}, "/render/msaa"},
        {"render size 0", "PUT", scene, J, doc([](json& d) { d["render"]["size"] = {0, 128}; }), {422}, "/render/size/0"},
        // --- non-finite and out-of-range numbers
        {"center 1e999", "POST", "/scenes", J, replaceInDoc("[0.3,0.4]", "[1e999,0.4]"), {400, 422}, ""},
        {"h -1e999", "POST", "/scenes", J, replaceInDoc("\"theta_min\"", "\"h\": -1e999, \"theta_min\""), {400, 422}, ""},
        {"theta_min == theta_max", "POST", "/scenes", J, withPlacementField("theta_max", 0), {422}, "/placements/0/theta_max"},
        // --- finite but out of bounds (issue #12.7) → 422 naming the field
        {"h 1e39", "POST", "/scenes", J, withPlacementField("h", 1e39), {422}, "/placements/0/h"},
        {"h 1e39 in a placement patch", "PATCH", scene + "/placements/elbow", J, R"({"h": 1e39})", {422}, "/placements/0/h"},
        {"theta_max 1e20", "POST", "/scenes", J, withPlacementField("theta_max", 1e20), {422}, "/placements/0/theta_max"},
        {"rotation 1e30", "POST", "/scenes", J, withPlacementField("rotation", 1e30), {422}, "/placements/0/rotation"},
        {"bump_strength 1e39", "PUT", scene, J, doc([](json& d) { d["render"]["bump_strength"] = 1e39; }), {422}, "/render/bump_strength"},
        {"displacement_scale 1e39", "PUT", scene, J, doc([](json& d) { d["render"]["displacement_scale"] = 1e39; }), {422}, "/render/displacement_scale"},
        {"pose time 1e12", "PATCH", scene + "/pose", J, R"({"time": 1e12})", {422}, "/pose/time"},
        {"negative h", "POST", "/scenes", J, withPlacementField("h", -1), {422}, "/placements/0/h"},
        {"zero scale", "POST", "/scenes", J, withPlacementField("scale", json::array({0, 0.1})), {422}, "/placements/0/scale/0"},
        {"negative pose time", "PATCH", scene + "/pose", J, R"({"time": -1})", {422}, "/pose/time"},
        // --- unknown names → 404
        {"unknown pattern", "POST", "/scenes", J, withPlacementField("pattern", "no_such_pattern"), {404}, "/placements/0/pattern"},
        {"unknown joint", "POST", "/scenes", J, withPlacementField("joint", "tail_07"), {404}, "/placements/0/joint"},
        {"unknown clip", "POST", "/scenes", J, doc([](json& d) { d["pose"]["animation"] = "moonwalk"; }), {404}, "/pose/animation"},
        {"unknown pose joint", "PATCH", scene + "/pose", J, R"({"joints": {"tail_07": {"axis_angles": {"x": 5}}}})", {404}, "/pose/joints/tail_07"},
        {"unknown morph target", "PATCH", scene + "/pose", J, R"({"morphs": {"frown": 1}})", {404}, "/pose/morphs/frown"},
        {"morph weight out of range", "PATCH", scene + "/pose", J, R"({"morphs": {"frown": 12}})", {422}, "/pose/morphs/frown"},
        {"unknown model id", "POST", "/scenes", J, withModel("m_0000000000000000"), {404}, "/model"},
        {"model ../../etc/passwd", "POST", "/scenes", J, withModel("../../etc/passwd"), {404, 422}, "/model"},
        {"model /etc/passwd", "POST", "/scenes", J, withModel("/etc/passwd"), {404, 422}, "/model"},
        {"model file:///etc/passwd", "POST", "/scenes", J, withModel("file:///etc/passwd"), {404, 422}, "/model"},
        {"model builtin:../x", "PUT", scene, J, withModel("builtin:../x"), {404, 422}, "/model"},
        {"model default.glb", "PUT", scene, J, withModel("models/default.glb"), {404, 422}, "/model"},
        {"pattern alias to a path", "POST", "/scenes", J, doc([](json& d) { d["patterns"] = {{"evil", "/etc/passwd"}}; d["placements"][0]["pattern"] = "evil"; }), {404}, "/patterns/evil"},
        {"pattern alias to a relative path", "POST", "/scenes", J, doc([](json& d) { d["patterns"] = {{"evil", "../patterns/crease.png"}}; }), {404}, "/patterns/evil"},
        {"pattern alias to a built-in", "POST", "/scenes", J, doc([](json& d) { d["patterns"] = {{"c", "crease"}}; }), {404, 422}, "/patterns/c"},
        {"base map path", "POST", "/scenes", J, doc([](json& d) { d["heightmap"]["base"] = "/etc/passwd"; }), {404}, "/heightmap/base"},
        {"unknown scene GET", "GET", "/scenes/s_0000000000000000", "", "", {404}, "id"},
        {"unknown scene PUT", "PUT", "/scenes/s_0000000000000000", J, smallScene().dump(), {404}, "id"},
        {"unknown scene DELETE", "DELETE", "/scenes/s_0000000000000000", "", "", {404}, "id"},
        {"unknown scene frame", "GET", "/scenes/s_0000000000000000/frame", "", "", {404}, "id"},
        {"unknown scene heightmap", "GET", "/scenes/s_0000000000000000/heightmaps/bump", "", "", {404}, "id"},
        {"unknown scene placement", "POST", "/scenes/s_0000000000000000/placements", J, placementOf("crease").dump(), {404}, "id"},
        {"unknown scene pose", "PATCH", "/scenes/s_0000000000000000/pose", J, "{}", {404}, "id"},
        {"unknown placement PATCH", "PATCH", scene + "/placements/nope", J, R"({"h": 2})", {404}, "pid"},
        {"unknown placement DELETE", "DELETE", scene + "/placements/nope", "", "", {404}, "pid"},
        {"changing a placement id", "PATCH", scene + "/placements/elbow", J, R"({"id": "other"})", {422}, "/id"},
        {"patch sets an invalid value", "PATCH", scene + "/placements/elbow", J, R"({"h": -2})", {422}, "/placements/0/h"},
        {"reorder missing an id", "PUT", scene + "/placements", J, R"(["elbow"])", {422}, ""},
        {"reorder duplicate ids", "PUT", scene + "/placements", J, R"(["elbow", "elbow"])", {422}, "/1"},
        {"reorder unknown id", "PUT", scene + "/placements", J, R"(["elbow", "nope"])", {404}, "/1"},
        {"reorder not an array", "PUT", scene + "/placements", J, R"({"order": ["elbow", "knee"]})", {422}, ""},
        {"reorder non-string id", "PUT", scene + "/placements", J, R"(["elbow", 7])", {422}, "/1"},
        // --- sign-in
        {"session with no body", "POST", "/session", J, "", {400}, "body"},
        {"session with no body or type", "POST", "/session", "", "", {415}, "body"},
        {"session non-JSON", "POST", "/session", J, "token=abc", {400}, "body"},
        {"session as a form", "POST", "/session", "application/x-www-form-urlencoded", "token=abc", {415}, "body"},
        {"session token not a string", "POST", "/session", J, R"({"token": 12345})", {422}, "/token"},
        {"session token null", "POST", "/session", J, R"({"token": null})", {422}, "/token"},
        {"session token an array", "POST", "/session", J, R"({"token": ["s3cret"]})", {422}, "/token"},
        {"session without token", "POST", "/session", J, R"({"password": "s3cret"})", {422}, "/token"},
        {"session body an array", "POST", "/session", J, R"(["s3cret"])", {422}, ""},
        {"session body a string", "POST", "/session", J, R"("s3cret")", {422}, ""},
        {"session nested deep", "POST", "/session", J, nested(100000, true), {400}, "body"},
        // --- frame and map parameters
        {"width=100000", "GET", scene + "/frame?width=100000", "", "", {413, 422}, "width"},
        {"width=99999999999", "GET", scene + "/frame?width=99999999999", "", "", {413, 422}, "width"},
        {"heightmap size 99999²", "PUT", scene, J, doc([](json& d) { d["heightmap"]["size"] = {99999, 99999}; }), {413, 422}, "/heightmap/size/0"},
        {"render size over the limit", "PUT", scene, J, doc([](json& d) { d["render"]["size"] = {4096, 64}; }), {413}, "/render/size/0"},
        {"width=0", "GET", scene + "/frame?width=0", "", "", {422}, "width"},
        {"height=-5", "GET", scene + "/frame?height=-5", "", "", {422}, "height"},
        {"msaa=3", "GET", scene + "/frame?msaa=3", "", "", {422}, "msaa"},
        {"pitch=200", "GET", scene + "/frame?pitch=200", "", "", {422}, "pitch"},
        {"width=abc", "GET", scene + "/frame?width=abc", "", "", {422}, "width"},
        {"width=12px", "GET", scene + "/frame?width=12px", "", "", {422}, "width"},
        {"yaw=nan", "GET", scene + "/frame?yaw=nan", "", "", {422}, "yaw"},
        {"yaw=inf", "GET", scene + "/frame?yaw=inf", "", "", {422}, "yaw"},
        {"distance=-1", "GET", scene + "/frame?distance=-1", "", "", {422}, "distance"},
        {"time=-1", "GET", scene + "/frame?time=-1", "", "", {422}, "time"},
        {"format=gif", "GET", scene + "/frame?format=gif", "", "", {422}, "format"},
        {"unknown heightmap", "GET", scene + "/heightmaps/roughness", "", "", {404}, "map"},
        {"bad heightmap format", "GET", scene + "/heightmaps/bump?format=tiff", "", "", {422}, "format"},
        {"normal map as f32", "GET", scene + "/heightmaps/normal?format=f32", "", "", {422}, "format"},
        {"uv-layout format=svg", "GET", "/models/builtin:default/uv-layout?format=svg", "", "", {422}, "format"},
        {"uv-layout size=0", "GET", "/models/builtin:default/uv-layout?format=png&size=0", "", "", {422}, "size"},
        {"pattern image size=0", "GET", "/patterns/crease/image?size=0", "", "", {422}, "size"},
        {"pattern image size=99999", "GET", "/patterns/crease/image?size=99999", "", "", {413, 422}, "size"},
        // --- frame previews: {placement id: merge patch}, nothing stored
        {"preview not JSON", "GET", scene + "/frame?preview=%7Bx", "", "", {422}, "preview"},
        {"preview an array", "GET", scene + "/frame?preview=%5B1%5D", "", "", {422}, "preview"},
        {"preview of an unknown placement", "GET", scene + "/frame?preview=%7B%22ghost%22%3A%7B%7D%7D", "", "", {422}, "preview"},
        {"preview with NaN-like h", "GET", scene + "/frame?preview=%7B%22elbow%22%3A%7B%22h%22%3A%22nan%22%7D%7D", "", "", {422}, "preview"},
        {"preview of 20 KB", "GET", scene + "/frame?preview=%7B%22elbow%22%3A%7B%22label%22%3A%22" + std::string(20000, 'a') + "%22%7D%7D", "", "", {422, 414, 431}, ""},
        // --- pick by texture point, drivers
        {"pick u outside [0,1]", "GET", scene + "/pick?u=1.5&v=0.5", "", "", {422}, "u"},
        {"pick u without v", "GET", scene + "/pick?u=0.5", "", "", {422}, "v"},
        {"pick u,v and x,y", "GET", scene + "/pick?u=0.5&v=0.5&x=1&y=1", "", "", {422}, "u"},
        {"drivers of an unknown revision", "GET", scene + "/drivers?revision=9999", "", "", {404}, "revision"},
        {"drivers at a negative time", "GET", scene + "/drivers?time=-1", "", "", {422}, "time"},
        // --- sweeps (SPEC §6 Sweep): steps 2..64 for a sheet, 2..1000 as JSON; cells size x size
        {"sweep without placement or clip", "GET", scene + "/sweep?steps=4", "", "", {422}, "placement"},
        {"sweep steps=0", "GET", scene + "/sweep?placement=elbow&steps=0", "", "", {422}, "steps"},
        {"sweep steps=1", "GET", scene + "/sweep?placement=elbow&steps=1", "", "", {422}, "steps"},
        {"sweep steps=10000", "GET", scene + "/sweep?placement=elbow&steps=10000", "", "", {422}, "steps"},
        {"sweep steps=65 as a sheet", "GET", scene + "/sweep?placement=elbow&steps=65", "", "", {422}, "steps"},
        {"sweep json steps=10000", "GET", scene + "/sweep?placement=elbow&steps=10000&format=json", "", "", {422}, "steps"},
        {"sweep clip steps=0", "GET", scene + "/sweep?clip=squat&steps=0&format=json", "", "", {422}, "steps"},
        {"sweep steps=abc", "GET", scene + "/sweep?placement=elbow&steps=abc", "", "", {422}, "steps"},
        {"sweep unknown placement", "GET", scene + "/sweep?placement=nope&steps=4", "", "", {404}, "placement"},
        {"sweep unknown placement json", "GET", scene + "/sweep?placement=nope&format=json", "", "", {404}, "placement"},
        {"sweep empty placement", "GET", scene + "/sweep?placement=&steps=4", "", "", {422}, "placement"},
        {"sweep unknown clip", "GET", scene + "/sweep?clip=moonwalk&steps=4", "", "", {404}, "clip"},
        {"sweep unknown clip json", "GET", scene + "/sweep?clip=moonwalk&format=json", "", "", {404}, "clip"},
        {"sweep size=0", "GET", scene + "/sweep?placement=elbow&size=0", "", "", {422}, "size"},
        {"sweep size=-3", "GET", scene + "/sweep?placement=elbow&size=-3", "", "", {422}, "size"},
        {"sweep size=100000", "GET", scene + "/sweep?placement=elbow&size=100000", "", "", {413, 422}, "size"},
        {"sweep size over the server limit", "GET", scene + "/sweep?placement=elbow&size=4096", "", "", {413}, "size"},
        {"sweep sheet over the server limit", "GET", scene + "/sweep?placement=elbow&steps=64&size=512", "", "", {413}, "size"},
        {"sweep width=64", "GET", scene + "/sweep?placement=elbow&width=64", "", "", {422}, "width"},
        {"sweep format=jpeg", "GET", scene + "/sweep?placement=elbow&format=jpeg", "", "", {422}, "format"},
        {"sweep pitch=200", "GET", scene + "/sweep?placement=elbow&steps=2&size=16&pitch=200", "", "", {422}, "pitch"},
        {"sweep time=-1", "GET", scene + "/sweep?placement=elbow&format=json&time=-1", "", "", {422}, "time"},
        {"sweep unknown scene", "GET", "/scenes/s_0000000000000000/sweep?placement=elbow", "", "", {404}, "id"},
        // --- uploads
        {"first 100 bytes of a .glb", "POST", "/models", GLB, truncatedGlb, {400, 415, 422}, "body"},
        {"half a .glb", "POST", "/models", GLB, halfGlb, {400, 415, 422}, "body"},
        {"random bytes as .glb", "POST", "/models", GLB, randomBytes, {400, 415}, "body"},
        {"glTF + garbage", "POST", "/models", GLB, glbGarbage, {400, 415, 422}, "body"},
        {"empty .glb", "POST", "/models", GLB, "", {400, 415}, "body"},
        {".gltf JSON body", "POST", "/models", GLB, gltfJson, {415}, "body"},
        {".gltf JSON body as model/gltf+json", "POST", "/models", "model/gltf+json", gltfJson, {415}, "body"},
        {"application/json to POST /models", "POST", "/models", J, str(cesium), {415}, "body"},
        {"text/plain to POST /scenes", "POST", "/scenes", "text/plain", smallScene().dump(), {415}, "body"},
        {"no content type to POST /scenes", "POST", "/scenes", "", smallScene().dump(), {415}, "body"},
        {"text/plain to PATCH pose", "PATCH", scene + "/pose", "text/plain", "{}", {415}, "body"},
        {"text/plain to POST /patterns", "POST", "/patterns", "text/plain", png, {415}, "body"},
        {"corrupt PNG", "POST", "/patterns", "image/png", corruptPng, {400, 415}, "body"},
        {"truncated PNG", "POST", "/patterns", "image/png", truncatedPng, {400, 415}, "body"},
        {"random bytes as image", "POST", "/patterns", "image/png", randomBytes, {400, 415}, "body"},
        {"empty image", "POST", "/patterns", "image/png", "", {400, 415}, "body"},
        {"image wider than the limit", "POST", "/patterns", "image/png", widePng, {413}, "body"},
        {"oversized model upload", "POST", "/models", GLB, oversized, {413}, "body"},
        {"oversized pattern upload", "POST", "/patterns", "image/png", oversized, {413}, "body"},
        {"oversized scene", "POST", "/scenes", J, oversized, {413}, "body"},
        // --- batch
        {"batch frames empty", "POST", "/render", J, batch(json::array()), {422}, "/frames"},
        {"batch frames not an array", "POST", "/render", J, batch({{"time", 0}}), {422}, "/frames"},
        {"batch 10000 frames", "POST", "/render", J, batch(tenThousand), {413}, "/frames"},
        {"batch frame without time or pose", "POST", "/render", J, batch(json::array({json::object()})), {422}, "/frames/0"},
        {"batch frame negative time", "POST", "/render", J, batch(json::array({{{"time", -2}}})), {422}, "/frames/0/time"},
        {"batch frame time a string", "POST", "/render", J, batch(json::array({{{"time", "0"}}})), {422}, "/frames/0/time"},
        {"batch frame pose unknown joint", "POST", "/render", J, batch(json::parse(R"([{"time": 0}, {"pose": {"joints": {"tail_07": {"axis_angles": {"x": 1}}}}}])")), {404}, "/frames/1/pose/joints/tail_07"},
        {"batch bad format", "POST", "/render", J, batch(json::array({{{"time", 0}}}), "gif"), {422}, "/format"},
        {"batch without scene", "POST", "/render", J, R"({"frames": [{"time": 0}]})", {422}, "/scene"},
        {"batch scene unknown model", "POST", "/render", J, R"({"scene": {"format": "dermis.scene/1", "model": "/etc/passwd"}, "frames": [{"time": 0}]})", {404}, "/scene/model"},
        {"batch is an array", "POST", "/render", J, "[]", {422}, ""},
        // --- conflicts and limits
        {"delete builtin:default", "DELETE", "/models/builtin:default", "", "", {409}, "id"},
        {"delete a built-in pattern", "DELETE", "/patterns/crease", "", "", {409}, "id"},
        {"delete a model in use", "DELETE", "/models/" + M, "", "", {409}, "id"},
        {"delete a pattern in use", "DELETE", "/patterns/" + P, "", "", {409}, "id"},
        {"delete an unknown pattern", "DELETE", "/patterns/p_0000000000000000", "", "", {404}, "id"},
        {"delete an unknown model", "DELETE", "/models/m_0000000000000000", "", "", {404}, "id"},
        {"placements over the limit", "PUT", scene, J, manyPlacements.dump(), {413}, "/placements"},
        // --- odd ids in the URL: never a file read
        {"model %2e%2e", "GET", "/models/%2e%2e", "", "", {404}, ""},
        {"model ..%2f..%2fetc%2fpasswd", "GET", "/models/..%2f..%2fetc%2fpasswd", "", "", {404}, ""},
        {"model builtin:..%2fdefault", "GET", "/models/builtin:..%2fdefault", "", "", {404}, ""},
        {"model builtin:default.glb", "GET", "/models/builtin:default.glb", "", "", {404}, "id"},
        {"pattern %2e%2e%2fmanifest.json", "GET", "/patterns/%2e%2e%2fmanifest.json/image", "", "", {404}, ""},
        {"pattern crease.png", "GET", "/patterns/crease.png/image", "", "", {404}, "id"},
        {"pattern ..", "DELETE", "/patterns/..", "", "", {404}, ""},
        {"scene %2e%2e", "GET", "/scenes/%2e%2e", "", "", {404}, ""},
        {"scene ../models", "GET", "/scenes/..%2Fmodels", "", "", {404}, ""},
        {"scene id with NUL", "GET", "/scenes/s_%00", "", "", {400, 404}, ""},
        {"scene file name", "GET", "/scenes/" + S + ".json", "", "", {404}, "id"},
    };
    // clang-format on
    EXPECT_GE(cases.size(), 60u);

    for (const BadCase& c : cases) {
        SCOPED_TRACE(c.name + " (" + c.method + " " + c.path.substr(0, 80) + ")");
        Reply r = h.call(c.method, c.path, c.body, c.contentType);
        ASSERT_NE(r.status, -1) << r;
        EXPECT_TRUE(std::find(c.statuses.begin(), c.statuses.end(), r.status) != c.statuses.end())
            << "expected " << ::testing::PrintToString(c.statuses) << ", got " << r;
        expectError(r, r.status, c.field);
        Reply health = h.get("/health");
        ASSERT_EQ(health.status, 200) << "after " << c.name << ": " << health;
    }

    // Nothing changed: the scene is as created, the uploads are still there.
    Reply after = h.get("/scenes/" + S);
    ASSERT_EQ(after.status, 200);
    EXPECT_EQ(after.js()["revision"], 1) << "a failed edit changed the scene";
    EXPECT_EQ(after.js()["scene"]["placements"].size(), 2u);
    EXPECT_EQ(h.get("/models/" + M).status, 200);
    EXPECT_EQ(h.get("/patterns/" + P + "/image").status, 200);
    for (const std::string& id : {S, SM, SP})
        EXPECT_EQ(h.del("/scenes/" + id).status, 204);
    EXPECT_EQ(h.del("/models/" + M).status, 204);
    EXPECT_EQ(h.del("/patterns/" + P).status, 204);
    std::cout << "[ BadInputHttpTest ] " << cases.size() << " bad-input cases\n";
}

} // namespace
