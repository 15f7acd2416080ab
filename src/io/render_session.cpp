#include "accretion/io/render_session.h"

#include <chrono>

#include <fmt/core.h>

#include "accretion/core/error.h"
#include "accretion/core/stop_signal.h"
#include "accretion/particles/particle_source.h"
#include "accretion/render/frame_plan.h"

namespace accretion {
namespace {

std::string bandText(const Accumulation& acc) {
    return acc.bandRows || acc.bandCols ? fmt::format(", pixels before row {} column {} done", acc.bandRows, acc.bandCols)
                                        : std::string();
}

}  // namespace

RenderSession::RenderSession(const Settings& settings, const std::string& checkpointFile, const std::string& settingsToml,
                             const Sharding& sharding, SessionOptions options, nlohmann::json& stats)
    : settings_(settings), sharding_(sharding), options_(options), stats_(stats),
      checkpoint_(checkpointFile, settingsToml, stats["shard"]), firstFrame_(sharding.first),
      resumed_(checkpoint_.load(options.resume, firstFrame_, sharding.end)) {
    if (resumed_) {
        // The same settings hold the same pixels; a file that says otherwise was not written by this run.
        const Accumulation& acc = resumed_->acc;
        const PixelWindow traced = planFrame(settings, FrameFacts{}).traced;
        if (acc.width != settings.camera.width || acc.height != settings.camera.height || acc.window != traced)
            throw InputError(fmt::format("{}: checkpoint of pixels [{}, {}) x [{}, {}) of {}x{}; this run lights [{}, {}) x [{}, {}) of {}x{}",
                                         checkpoint_.file().string(), acc.window.x0, acc.window.x1, acc.window.y0,
                                         acc.window.y1, acc.width, acc.height, traced.x0, traced.x1, traced.y0, traced.y1,
                                         settings.camera.width, settings.camera.height));
        for (const auto& f : resumed_->header.at("finished_frames")) stats_["frames"].push_back(f);
        firstFrame_ = resumed_->header.at("frame").get<std::uint32_t>();
        if (!options.quiet)
            fmt::print(stderr, "accretion: resuming {} at frame {}, chunk {}{}\n", checkpoint_.file().string(), firstFrame_,
                       acc.nextChunk, bandText(acc));
    } else if (options.resume && !options.quiet) {  // nothing to resume: start afresh
        fmt::print(stderr, "accretion: {}: starting from the beginning\n",
                   sharding.accumulating ? fmt::format("no checkpoint at {}", checkpoint_.file().string())
                                         : std::string("restir keeps reservoir history across frames and is not checkpointed"));
    }
}

void RenderSession::saveCheckpoint(std::uint32_t frame, const Accumulation& acc) {
    checkpoint_.save(frame, acc, stats_["frames"]);
    lastCheckpoint_ = std::chrono::steady_clock::now();
}

void RenderSession::interrupt(int signal, std::uint32_t frame, const Accumulation& acc) const {
    fmt::print(stderr, "accretion: {}: checkpoint {} (frame {}, chunk {}{}); continue with --resume\n", StopSignal::name(signal),
               checkpoint_.file().string(), frame, acc.nextChunk, bandText(acc));
    throw Interrupted{signal};
}

// restir keeps reservoir history across frames: no checkpoint, the frames done are kept.
void RenderSession::stopBetweenFrames(int signal, std::uint32_t next) const {
    fmt::print(stderr, "accretion: {}: stopped before frame {}; frames {}..{} are written ({} keeps reservoir history "
                       "across frames and is not checkpointed: render the rest with --frames {}:{})\n",
               StopSignal::name(signal), next, firstFrame_, next - 1, enumName(settings_.render.estimator), next, sharding_.end);
    throw Interrupted{signal};
}

RenderSession::Totals RenderSession::run(const FrameWriter& write) {
    const auto start = std::chrono::steady_clock::now();
    // One signal path for every estimator: SIGINT and SIGTERM stop at the next
    // safe point (a chunk of an accumulating estimator, else the end of a
    // frame), with the frames written so far whole and the lock released.
    const StopSignal stop;
    lastCheckpoint_ = start;
    FrameRenderer renderer(settings_, ParticleSource(settings_), RenderOptions{options_.quiet});
    Totals totals;
    Accumulation sums;  // the frame's lighting sums (reused: no reallocation per frame)
    for (std::uint32_t frame = firstFrame_; frame < sharding_.end; ++frame) {
        if (!options_.quiet)
            fmt::print(stderr, "accretion: frame {} ({}/{})\n", frame, frame - settings_.render.frame_start + 1,
                       settings_.render.frames);
        LightingSession session;
        session.shard = sharding_.samples();
        session.result = &sums;
        if (resumed_ && resumed_->header.at("frame").get<std::uint32_t>() == frame) session.resume = &resumed_->acc;
        session.afterChunk = [&](const Accumulation& acc) {
            const int signal = stop.pending();
            const double since = std::chrono::duration<double>(std::chrono::steady_clock::now() - lastCheckpoint_).count();
            if (signal || (options_.checkpointEvery > 0.0 && since >= options_.checkpointEvery)) saveCheckpoint(frame, acc);
            if (signal) interrupt(signal, frame, acc);
            return true;
        };
        FrameStats fs;
        const FrameImage image = renderer.render(frame, fs, sharding_.accumulating ? &session : nullptr);
        resumed_.reset();
        stats_["frames"].push_back(write(frame, image, fs, sums));
        totals.shadowRays += fs.lighting.shadowRays;
        totals.lightingSeconds += fs.timer.seconds(Pass::estimateLighting);
        // Stopped between frames: the next frame starts from its first chunk.
        if (const int signal = stop.pending(); signal && frame + 1 < sharding_.end) {
            if (!sharding_.accumulating) stopBetweenFrames(signal, frame + 1);
            Accumulation next;
            next.reset(settings_.camera.width, settings_.camera.height,
                       sharding_.bySamples ? planLighting(settings_.render, settings_.camera.height, sharding_.shard).begin : 0,
                       &renderer.plan().traced);
            saveCheckpoint(frame + 1, next);
            interrupt(signal, frame + 1, next);
        }
    }
    totals.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return totals;
}

}  // namespace accretion
