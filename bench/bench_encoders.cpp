// dermis-bench part 3: every frame format's encode time and size on a real frame (the default
// scene, posed, 512² and 1024²), as the server encodes them: PNG and lossless WebP without alpha
// (the frame route's), JPEG quality 90, EXR half RGBA (encodeFrame).
#include "bench_parts.hpp"

#include "io/frame_io.hpp"
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
                if (!encoded) {
                    std::cerr << encoded.error().message << "\n";
                    return 1;
                }
                bytes = encoded->size();
                if (r > 0) ms.push_back(t);
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

} // namespace dermis::bench
