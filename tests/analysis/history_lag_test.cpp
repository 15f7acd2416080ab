// The lag of a per-particle history against closed forms: a light changing
// linearly in time, averaged by each start rule, a particle that leaves the
// view, pixels weighted by the particles' sizes, and a still light (no lag).
#include <catch2/catch.hpp>

#include <cmath>

#include "accretion/analysis/history_lag.h"
#include "accretion/analysis/image_metrics.h"
#include "accretion/core/gbuffer_texel_layout.h"

using namespace accretion;

namespace {

/// Frames of `pixels` pixels of particle 7 (the rest see none) whose light
/// at frame t is a + b t in every channel.
void addLinear(HistoryLag& lag, std::uint32_t frames, double a, double b, std::size_t pixels = 3) {
    for (std::uint32_t t = 0; t < frames; ++t) {
        std::vector<Vec3> light(pixels + 2, Vec3(0.0f));
        std::vector<std::uint32_t> id(pixels + 2, kNoParticle);
        for (std::size_t p = 0; p < pixels; ++p) {
            light[p] = Vec3(float(a + b * t));
            id[p] = 7;
        }
        lag.addFrame(t, light, id);
    }
}

}  // namespace

TEST_CASE("HistoryLag: a light a + b t averaged from its first frame lags by h (1 - h^T) / (1 - h) frames", "[analysis][lag]") {
    // hist_T = h^T L(0) + sum_{k<T} (1 - h) h^k L(T - k): its weights sum to 1
    // and their mean age is sum_{k<T} k (1 - h) h^k + T h^T = h (1 - h^T) / (1 - h).
    const double a = 1.0, b = 0.01, h = 0.9;
    const std::uint32_t T = 30;
    HistoryLag lag({{h, HistoryStart::first}});
    addLinear(lag, T + 1, a, b);
    const LagOutcome o = lag.outcomes().at(0);
    const double now = a + b * T, hist = a + b * (T - h * (1.0 - std::pow(h, T)) / (1.0 - h));
    CHECK(o.particles == 1);
    CHECK(o.fresh == 0);
    CHECK(o.now == Approx(3.0 * float(now)).epsilon(1e-6));
    CHECK(o.energyPct() == Approx(100.0 * (hist / float(now) - 1.0)).epsilon(1e-4));
    const double w = 1.0 / (double(float(now)) * float(now) + kRelMseEpsilon);
    CHECK(o.relMSE == Approx((hist - float(now)) * (hist - float(now)) * w * 3.0 / 5.0).epsilon(1e-3));  // 3 of 5 pixels lit
}

TEST_CASE("HistoryLag: with history_start mean the first 1 / (1 - h) frames are a running mean", "[analysis][lag]") {
    const double a = 2.0, b = -0.05, h = 0.75;  // 1 / (1 - h) = 4 frames
    SECTION("within them: the mean of L(0..T), a + b T / 2") {
        HistoryLag lag({{h, HistoryStart::mean}});
        addLinear(lag, 4, a, b);  // T = 3
        const LagOutcome o = lag.outcomes().at(0);
        CHECK(o.energyPct() == Approx(100.0 * ((a + b * 1.5) / (a + b * 3.0) - 1.0)).epsilon(1e-4));
    }
    SECTION("past them: the running mean of 4 frames, then the exponential average") {
        // hist_T = h^m (a + 1.5 b) + (1 - h^m)(a + b T) - b [h (1 - h^m) / (1 - h) - m h^m], m = T - 3.
        const std::uint32_t T = 20, m = T - 3;
        HistoryLag lag({{h, HistoryStart::mean}});
        addLinear(lag, T + 1, a, b);
        const double hm = std::pow(h, m);
        const double hist = hm * (a + 1.5 * b) + (1.0 - hm) * (a + b * T) - b * (h * (1.0 - hm) / (1.0 - h) - m * hm);
        CHECK(lag.outcomes().at(0).energyPct() == Approx(100.0 * (hist / (a + b * T) - 1.0)).epsilon(1e-4));
    }
}

TEST_CASE("HistoryLag: a particle out of view loses its history, and pixels weigh their particles", "[analysis][lag]") {
    // Particle 1 (1 pixel) is lit 1 + t and in view every frame; particle 2 (3
    // pixels) is lit 10 (constant) in frames 0-1, out of view in frame 2 and
    // back in frame 3 lit 4: fresh there, its history its light now.
    const double h = 0.5;
    HistoryLag lag({{h, HistoryStart::first}, {0.0, HistoryStart::first}});
    for (std::uint32_t t = 0; t < 4; ++t) {
        std::vector<Vec3> light(4, Vec3(0.0f));
        std::vector<std::uint32_t> id(4, kNoParticle);
        light[0] = Vec3(float(1 + t));
        id[0] = 1;
        if (t != 2)
            for (int p = 1; p < 4; ++p) {
                light[p] = Vec3(t == 3 ? 4.0f : 10.0f);
                id[p] = 2;
            }
        lag.addFrame(t, light, id);
    }
    const auto o = lag.outcomes();
    // Particle 1: first start, h = 0.5: 1, 1.5, 2.25, 3.125 against 4.
    CHECK(o[0].particles == 2);
    CHECK(o[0].fresh == 1);
    CHECK(o[0].now == Approx(4.0 + 3.0 * 4.0));
    CHECK(o[0].history == Approx(3.125 + 3.0 * 4.0));
    CHECK(o[0].energyPct() == Approx(100.0 * (15.125 / 16.0 - 1.0)));
    // Measured at pixel 0 alone (a crop): particle 1's 3.125 against 4.
    const auto crop = lag.outcomes({true, false, false, false});
    CHECK(crop[0].particles == 1);
    CHECK(crop[0].fresh == 0);
    CHECK(crop[0].energyPct() == Approx(100.0 * (3.125 / 4.0 - 1.0)));
    CHECK(crop[0].relMSE == Approx(0.875 * 0.875 / (16.0 + kRelMseEpsilon)));
    CHECK(lag.trend({true, false, false, false})[0].ratio == Approx(1.0 / 4.0));
    // h = 0: no history, no lag.
    CHECK(o[1].energyPct() == 0.0);
    CHECK(o[1].relMSE == 0.0);
    // The trend: the last frame's pixels' particles in each frame, over now.
    const auto trend = lag.trend();
    REQUIRE(trend.size() == 4);
    CHECK(trend[0].ratio == Approx((1.0 + 30.0) / 16.0));
    CHECK(trend[0].tracked == 1.0);
    CHECK(trend[2].ratio == Approx(3.0 / 4.0));  // particle 2 out of view: particle 1's pixel alone
    CHECK(trend[2].tracked == 0.25);
    CHECK(trend[3].ratio == 1.0);
}

TEST_CASE("HistoryLag: a still light has no lag, however long the history", "[analysis][lag]") {
    HistoryLag lag({{0.99, HistoryStart::first}, {0.95, HistoryStart::mean}});
    addLinear(lag, 50, 0.37, 0.0);
    for (const LagOutcome& o : lag.outcomes()) {
        CHECK(o.energyPct() == 0.0);
        CHECK(o.relMSE == 0.0);
    }
}
