// dermis-bench part 3: every frame format's encode time and size on a real frame (the default
// scene, posed, 512² and 1024²), as the server encodes them: PNG and lossless WebP without alpha
// (the frame route's), JPEG quality 90, EXR half RGBA (encodeFrame; reported unavailable where
// the OpenImageIO module is not there).
#include "bench_parts.hpp"

#include "io/frame_io.hpp"
#include "io/image_io.hpp"
#include "io/webp_encode.hpp"

#include <functional>
#include <iostream>
#include <string>

namespace dermis::bench {

int benchEncoders(Renderer& renderer, const DefaultScene& ds, int repeat, nlohmann::json& out) {
    for (int size : {512, 1024}) {
        Scene scene = ds.scene;
        scene.render.size = {size, size};
        FrameOverrides overrides;
        overrides.time = ds.clipDuration * 0.5;
        auto plan = planFrame(scene, *ds.model, ds.images, nullptr, overrides);
        if (!plan) {
            std::cerr << plan.error().message << "\n";
            return 1;
        }
        auto frame = renderer.renderFrame(frameRequest(*plan, ds.model));
        if (!frame) {
            std::cerr << frame.error().message << "\n";
            return 1;
        }
        const Image8& img = frame->image;
        const std::pair<const char*, std::function<Result<std::vector<std::uint8_t>>()>> formats[] = {
            {"png", [&] { return encodePng(img, false); }},
            {"jpeg", [&] { return encodeJpeg(img, 90); }},
            {"webp_lossless", [&] { return encodeWebpLossless(img, false); }},
            {"exr", [&] { return encodeFrame(img, FrameFormat::Exr); }},
        };
        for (const auto& [name, encode] : formats) {
            std::vector<double> ms;
            std::size_t bytes = 0;
            for (int r = 0; r <= repeat; ++r) {
                const auto t0 = std::chrono::steady_clock::now();
                auto encoded = encode();
                const double t = msSince(t0);
                if (!encoded && encoded.error().code == ErrorCode::Unavailable) break;
                if (!encoded) {
                    std::cerr << encoded.error().message << "\n";
                    return 1;
                }
                bytes = encoded->size();
                if (r > 0) ms.push_back(t);
            }
            if (ms.empty()) {
                // A build or image without the OpenImageIO module (docs/container.md): no EXR.
                out.push_back({{"format", name}, {"frame_size", size}, {"unavailable", true}});
                continue;
            }
            out.push_back({{"format", name},
                           {"frame_size", size},
                           {"encode_ms", round2(medianMs(ms))},
                           {"bytes", bytes},
                           {"repetitions", ms.size()}});
        }
    }
    return 0;
}

int benchHeightmapFetch(Renderer& renderer, const DefaultScene& ds, int repeat, nlohmann::json& out) {
    std::vector<double> changed, same, f32, png16;
    for (int r = 0; r <= repeat; ++r) {
        FrameOverrides overrides;
        overrides.time = ds.clipDuration * (0.2 + 0.6 * r / (repeat + 1.0));
        auto plan = planFrame(ds.scene, *ds.model, ds.images, nullptr, overrides);
        if (!plan) {
            std::cerr << plan.error().message << "\n";
            return 1;
        }
        auto t0 = std::chrono::steady_clock::now();
        auto maps = renderer.bakeHeightMaps(plan->heights);
        const double tChanged = msSince(t0);
        t0 = std::chrono::steady_clock::now();
        auto again = renderer.bakeHeightMaps(plan->heights);
        const double tSame = msSince(t0);
        if (!maps || !again) {
            std::cerr << (maps ? again.error() : maps.error()).message << "\n";
            return 1;
        }
        t0 = std::chrono::steady_clock::now();
        auto a = encodeF32(maps->displacement);
        const double tF32 = msSince(t0);
        t0 = std::chrono::steady_clock::now();
        auto b = encodeHeight16Png(maps->bump);
        const double tPng = msSince(t0);
        if (!a || !b) {
            std::cerr << (a ? b.error() : a.error()).message << "\n";
            return 1;
        }
        if (r == 0) continue; // the first bake pays for uploads
        changed.push_back(tChanged);
        same.push_back(tSame);
        f32.push_back(tF32);
        png16.push_back(tPng);
    }
    out = {{"map_size", ds.scene.heightmapSize[0]},
           {"bake_new_pose_ms", round2(medianMs(changed))},
           {"bake_same_inputs_ms", round2(medianMs(same))},
           {"encode_f32_ms", round2(medianMs(f32))},
           {"encode_png16_ms", round2(medianMs(png16))},
           {"repetitions", changed.size()}};
    return 0;
}

} // namespace dermis::bench
