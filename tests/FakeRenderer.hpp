// Test helper: a FrameRenderer without GL, injected into a Service so that ServiceTest covers
// edits, limits, errors and locking directly. Height maps come from the CPU reference; a frame is
// a flat image whose colour depends on what was asked (camera, pose, t values), so a test can see
// that an edit changed it. It can hold renders at a gate to test what else runs meanwhile.
#pragma once

#include "core/frame_plan.hpp"
#include "gl/renderer.hpp"

#include <chrono>
#include <condition_variable>
#include <mutex>

namespace dermis::test {

class FakeRenderer final : public FrameRenderer {
public:
    FakeRenderer() {
        info_.backend = "fake";
        info_.renderer = "CPU fake (tests)";
    }
    const RendererInfo& info() const override { return info_; }
    void forgetPattern(std::uint64_t) override { ++forgottenPatterns; }
    void forgetModel(const std::shared_ptr<const Model>&) override { ++forgottenModels; }
    int forgottenPatterns = 0, forgottenModels = 0; ///< forget* calls (the service's cache evictions, deletes)

    Result<HeightMaps> bakeHeightMaps(const HeightPassInput& in) override {
        enterGate();
        std::lock_guard<std::mutex> lock(mutex_);
        ++bakes_;
        return dermis::bakeHeightMaps(in, 1);
    }

    Result<FrameResult> renderFrame(const FrameRequest& req) override {
        enterGate();
        std::lock_guard<std::mutex> lock(mutex_);
        ++frames_;
        last_ = req.render;
        lastEnvironment_ = req.environment;
        double sum = req.render.camera.yaw * 0.37 + req.render.camera.pitch * 0.11;
        if (req.heights)
            for (const BakePlacement& p : req.heights->placements) sum += p.t * 97.0 + p.h;
        for (const glm::mat4& m : req.world) sum += m[3][0] * 13.0 + m[3][1] * 7.0 + m[3][2] * 3.0;
        FrameResult out;
        out.image.width = req.render.size[0];
        out.image.height = req.render.size[1];
        out.image.rgba.resize(static_cast<std::size_t>(out.image.width) * out.image.height * 4);
        const auto c = static_cast<std::uint32_t>(static_cast<long long>(sum * 1000.0) & 0xffffff);
        for (std::size_t i = 0; i < out.image.rgba.size(); i += 4) {
            out.image.rgba[i] = static_cast<std::uint8_t>(c);
            out.image.rgba[i + 1] = static_cast<std::uint8_t>(c >> 8);
            out.image.rgba[i + 2] = static_cast<std::uint8_t>(c >> 16);
            out.image.rgba[i + 3] = 255;
        }
        return out;
    }

    /// From now on renders wait at the gate until release().
    void block() {
        std::lock_guard<std::mutex> lock(gateMutex_);
        blocked_ = true;
    }
    void release() {
        {
            std::lock_guard<std::mutex> lock(gateMutex_);
            blocked_ = false;
        }
        gateCv_.notify_all();
    }
    /// Waits until a render is waiting at the gate (false after `ms`).
    bool waitUntilEntered(int ms) {
        std::unique_lock<std::mutex> lock(gateMutex_);
        return gateCv_.wait_for(lock, std::chrono::milliseconds(ms), [&] { return waiting_ > 0; });
    }

    int frames() const {
        std::lock_guard<std::mutex> lock(mutex_);
        return frames_;
    }
    int bakes() const {
        std::lock_guard<std::mutex> lock(mutex_);
        return bakes_;
    }
    RenderSettings lastSettings() const {
        std::lock_guard<std::mutex> lock(mutex_);
        return last_;
    }
    /// The last frame's environment image (null: the built-in studio, or none decoded).
    std::shared_ptr<const EnvironmentImage> lastEnvironment() const {
        std::lock_guard<std::mutex> lock(mutex_);
        return lastEnvironment_;
    }

private:
    void enterGate() {
        std::unique_lock<std::mutex> lock(gateMutex_);
        ++waiting_;
        gateCv_.notify_all();
        gateCv_.wait(lock, [&] { return !blocked_; });
        --waiting_;
    }

    RendererInfo info_;
    mutable std::mutex mutex_;
    int frames_ = 0, bakes_ = 0;
    RenderSettings last_;
    std::shared_ptr<const EnvironmentImage> lastEnvironment_;
    std::mutex gateMutex_;
    std::condition_variable gateCv_;
    bool blocked_ = false;
    int waiting_ = 0;
};

} // namespace dermis::test
