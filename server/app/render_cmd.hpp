// dermis-server — the offline `render` command (frames of a scene to image files, a range or a
// farm shard of it) and `farm-verify` (are all frames of a range there and intact?).
//
//   render --scene S.json --out frame.png [--time T]
//   render --scene S.json --out dir/frame_%04d.png --frames A:B:STEP [--shard I/N | auto/N] [--resume]
//   farm-verify dir/frame_%04d.png|dir --frames A:B:STEP [--json]
//
// A range renders frame k at A + k·STEP into the pattern's k-th file; --shard renders only the
// frames k with k mod N = I (core/frame_range.hpp) and then writes the shard's manifest
// (io/farm_manifest.hpp). With --shard or --resume, frames whose file exists are skipped: every
// file is written atomically (temp + rename), so a file that exists is complete. Rendering is
// deterministic on one machine: a frame is byte-identical whichever shard renders it.
// Both return the process exit code: 0 ok, 1 an error (printed as "dermis-server: error: …") or
// frames missing/corrupt (farm-verify).
#pragma once

#include <string>

namespace dermis::app {

struct RenderArgs {
    std::string scene, out, gl = "auto", frames, size, content, view = "shaded", shard;
    double time = 0.0;
    int msaa = 0; ///< 0: the scene's render.msaa (given: MSAA with that many samples)
    std::string aa; ///< "": the scene's render.aa (or MSAA when msaa is given); auto|msaa|post|none
    std::string shading;     ///< "": the scene's render.shading; legacy|pbr
    std::string toneMapping; ///< "": the scene's render.tone_mapping; neutral|aces|none
    double exposure = -1.0;  ///< < 0: the scene's render.exposure
    std::string environment; ///< "": the default studio environment; else an .hdr / .exr file
    /// "": the scene's render.key_light; "off": none; "X,Y,Z" or "X,Y,Z,INTENSITY": a key light
    /// towards (X, Y, Z) (world), its other members the scene's light's or the defaults.
    std::string keyLight;
    bool noShadows = false; ///< the key light casts no shadow
    bool hasTime = false, heightmaps = false, resume = false;
    /// Print where the time went as one JSON line on stderr: start-up (context, programs, scene
    /// load, the wait for the renderer), the first frame's stages (with a GL sync between them)
    /// and its encode + write; the wall time outside runRender is the process's start and exit.
    bool timings = false;
};

int runRender(const RenderArgs& a);

struct FarmVerifyArgs {
    std::string out, frames;
    bool json = false;
};

int runFarmVerify(const FarmVerifyArgs& a);

} // namespace dermis::app
