#include "accretion/render/accumulation.h"

#include <algorithm>

#include <fmt/format.h>

#include "accretion/core/error.h"
#include "accretion/scene/estimator_table.h"

namespace accretion {

LightingPlan planLighting(const RenderSettings& render, std::uint32_t height, Shard shard) {
    LightingPlan plan;
    const EstimatorInfo& e = estimatorInfo(render.estimator);
    plan.exact = e.sums;
    plan.adaptive = e.adaptive && render.target_stderr > 0.0;
    plan.samples = render.samples;
    plan.chunksPerRound = plan.exact ? (height + LightingPlan::kChunkRows - 1) / LightingPlan::kChunkRows
                                     : (render.samples + LightingPlan::kChunkSamples - 1) / LightingPlan::kChunkSamples;
    plan.chunksPerRound = std::max(plan.chunksPerRound, 1u);
    plan.rounds = plan.adaptive ? std::max(1u, render.max_samples / render.samples) : 1u;
    const std::uint64_t total = std::uint64_t(plan.chunksPerRound) * plan.rounds;
    if (!shard.whole()) {
        if (plan.adaptive)
            throw InputError(fmt::format("command line --shard {}/{}: adaptive sampling (render.target_stderr) decides per pixel when "
                                         "to stop, so its samples cannot be split; shard frames instead (--frames)",
                                         shard.index, shard.count));
        if (total < shard.count)
            throw InputError(fmt::format("command line --shard {}/{}: the frame has only {} chunks ({}) to split", shard.index,
                                         shard.count, total,
                                         plan.exact ? fmt::format("exact: {} row each", LightingPlan::kChunkRows)
                                                    : fmt::format("{} samples each", LightingPlan::kChunkSamples)));
    }
    plan.begin = total * shard.index / shard.count;
    plan.end = total * (shard.index + 1) / shard.count;
    return plan;
}

void Accumulation::reset(std::uint32_t w, std::uint32_t h, std::uint64_t firstChunk, const PixelWindow* lit) {
    width = w;
    height = h;
    window = lit ? *lit : PixelWindow::whole(w, h);
    ACC_CHECK(PixelWindow::whole(w, h).contains(window));
    const std::size_t count = pixels();
    sum.assign(count, DVec3(0.0));
    sumSq.assign(count, DVec3(0.0));
    n.assign(count, 0);
    done.assign(count, 0);
    rejected.assign(count, 0);
    nextChunk = firstChunk;
    bandRows = bandCols = 0;
}

void Accumulation::merge(const Accumulation& o) {
    ACC_CHECK(o.width == width && o.height == height && o.window == window);
    for (std::size_t px = 0; px < pixels(); ++px) {
        sum[px] += o.sum[px];
        sumSq[px] += o.sumSq[px];
        n[px] += o.n[px];
        done[px] = done[px] | o.done[px];
        rejected[px] += o.rejected[px];
    }
}

std::uint32_t nextBandPixels(double pixelChunkSeconds, std::uint64_t span, std::uint32_t previous, std::uint32_t groupPixels,
                             std::uint32_t cores, double bandSeconds) {
    const double least = double(groupPixels) * std::max(cores, 1u);
    if (!(pixelChunkSeconds > 0.0) || previous == 0) return std::uint32_t(least);
    const double fit = bandSeconds / (pixelChunkSeconds * double(std::max<std::uint64_t>(span, 1)));
    return std::uint32_t(std::clamp(std::min(fit, 4.0 * previous), least, 1e9));
}

}  // namespace accretion
