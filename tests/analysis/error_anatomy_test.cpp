// relMSE's anatomy (what the seeds share, what they do not) and the floor
// of one value a particle, against closed forms, relMSE as computeErrors
// measures it, and Monte Carlo with a stated confidence.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include "accretion/analysis/error_anatomy.h"
#include "accretion/analysis/image_metrics.h"
#include "accretion/core/gbuffer_texel_layout.h"

using namespace accretion;

namespace {

constexpr double kEps = kRelMseEpsilon;

/// The seeds' images' errors summed and square-summed, as bias keeps them.
struct Sums {
    std::vector<DVec3> s1, s2;
    explicit Sums(std::size_t pixels) : s1(pixels, DVec3(0.0)), s2(pixels, DVec3(0.0)) {}
    void add(const std::vector<Vec3>& x, const std::vector<Vec3>& ref) {
        for (std::size_t p = 0; p < x.size(); ++p) {
            const DVec3 d = DVec3(x[p]) - DVec3(ref[p]);
            s1[p] += d;
            s2[p] += d * d;
        }
    }
};

}  // namespace

TEST_CASE("splitRelMse: two seeds a +- d at a pixel in closed form", "[analysis][anatomy]") {
    // Errors a + d and a - d: mean a, unbiased variance 2 d^2, so noise is
    // 2 d^2 w and persistent (a^2 - d^2) w, w = 1 / (ref^2 + eps); their sum
    // is the seeds' mean squared error a^2 + d^2, times w.
    const double a = 0.3, d = 0.2, r = 2.0, w = 1.0 / (r * r + kEps);
    const std::vector<Vec3> ref = {Vec3(float(r))};
    Sums s(1);
    s.add({Vec3(float(r + a + d))}, ref);
    s.add({Vec3(float(r + a - d))}, ref);
    const ErrorAnatomy e = splitRelMse(s.s1, s.s2, 2.0, ref, {}, kEps);
    CHECK(e.noise == Approx(2.0 * d * d * w).epsilon(1e-5));
    CHECK(e.persistent == Approx((a * a - d * d) * w).epsilon(1e-5));
    // The reference's own noise s is taken from the persistent part alone.
    const double se = 0.1;
    const ErrorAnatomy f = splitRelMse(s.s1, s.s2, 2.0, ref, {Vec3(float(se))}, kEps);
    CHECK(f.noise == Approx(e.noise).epsilon(1e-12));
    CHECK(f.persistent == Approx((a * a - d * d - se * se) * w).epsilon(1e-5));
}

TEST_CASE("splitRelMse: its parts sum to the seeds' mean relMSE as computeErrors measures it", "[analysis][anatomy]") {
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<float> u(0.0f, 3.0f);
    std::normal_distribution<float> g(0.0f, 0.4f);
    const std::size_t pixels = 500;
    std::vector<Vec3> ref(pixels), stderr(pixels), bias(pixels);
    for (std::size_t p = 0; p < pixels; ++p) {
        ref[p] = Vec3(u(rng), u(rng), p % 7 == 0 ? 0.0f : u(rng));
        stderr[p] = Vec3(0.01f * u(rng));
        bias[p] = Vec3(g(rng));
    }
    Sums s(pixels);
    double mean = 0.0;
    const int seeds = 5;
    for (int k = 0; k < seeds; ++k) {
        std::vector<Vec3> x(pixels);
        for (std::size_t p = 0; p < pixels; ++p) x[p] = ref[p] + bias[p] + Vec3(g(rng), g(rng), g(rng));
        s.add(x, ref);
        const ErrorMetrics m = computeErrors(x, ref, &stderr);
        mean += (m.relMSE - m.relMSEFloor) / seeds;
    }
    const ErrorAnatomy e = splitRelMse(s.s1, s.s2, seeds, ref, stderr, kEps);
    CHECK(e.persistent + e.noise == Approx(mean).epsilon(1e-9));
    CHECK(e.persistent > 0.0);
    CHECK(e.noise > 0.0);
}

TEST_CASE("splitRelMse: a known bias and noise recovered, 99.99% bounds", "[analysis][anatomy][statistical]") {
    // Every channel of every pixel: error b + N(0, sigma^2) in each of S = 4
    // seeds, the reference 1 (w = 1 / 1.01). persistent estimates b^2 w,
    // noise sigma^2 w. One term of persistent, m^2 - v / S with m ~ N(b,
    // sigma^2 / S) and v independent of it, has variance 4 b^2 sigma^2 / S +
    // 2 sigma^4 / S^2 + 2 sigma^4 / (S^2 (S - 1)); one of noise 2 sigma^4 /
    // (S - 1). Over n terms the bounds are 3.9 standard errors (99.99%).
    const double S = 4.0, sigma = 1.0, w = 1.0 / (1.0 + kEps);
    const std::size_t pixels = 100000;
    const double n = 3.0 * pixels;
    for (const double b : {0.0, 0.5}) {
        INFO("bias " << b);
        std::mt19937_64 rng(b == 0.0 ? 11 : 12);
        std::normal_distribution<double> g(0.0, sigma);
        const std::vector<Vec3> ref(pixels, Vec3(1.0f));
        Sums s(pixels);
        for (int k = 0; k < int(S); ++k) {
            std::vector<Vec3> x(pixels);
            for (Vec3& v : x) v = Vec3(float(1.0 + b + g(rng)), float(1.0 + b + g(rng)), float(1.0 + b + g(rng)));
            s.add(x, ref);
        }
        const ErrorAnatomy e = splitRelMse(s.s1, s.s2, S, ref, {}, kEps);
        const double s4 = sigma * sigma * sigma * sigma;
        const double sdPersistent = w * std::sqrt((4 * b * b * sigma * sigma / S + 2 * s4 / (S * S) + 2 * s4 / (S * S * (S - 1))) / n);
        const double sdNoise = w * std::sqrt(2 * s4 / (S - 1) / n);
        CHECK(std::fabs(e.persistent - b * b * w) < 3.9 * sdPersistent);
        CHECK(std::fabs(e.noise - sigma * sigma * w) < 3.9 * sdNoise);
    }
}

TEST_CASE("particleMeanFloor: each pixel its particle's mean, in closed form", "[analysis][anatomy]") {
    // Particle 7 covers three pixels of Lr 1, 2, 3 (grey), particle 9 one of
    // 4, and one pixel sees no particle: the means are 2 and 4, so the floor
    // is (1 / (1 + eps) + 0 + 1 / (9 + eps)) over the 5 pixels (x 3
    // channels, each the same). The median particle covers 2 pixels (of 3 and 1).
    const std::vector<Vec3> ref = {Vec3(1.0f), Vec3(5.0f), Vec3(2.0f), Vec3(3.0f), Vec3(4.0f)};
    const std::vector<std::uint32_t> ids = {7, kNoParticle, 7, 7, 9};
    const ParticleMeanFloor f = particleMeanFloor(ref, ids, {}, kEps);
    CHECK(f.relMSE == Approx((1.0 / (1.0 + kEps) + 1.0 / (9.0 + kEps)) / 5.0).epsilon(1e-9));
    CHECK(f.particles == 2);
    CHECK(f.medianPixels == 2.0);
    // A reference noise s of every pixel: particle 7's pixels lose s^2 (1 - 1/3) each.
    const double s = 0.1;
    const ParticleMeanFloor g = particleMeanFloor(ref, ids, std::vector<Vec3>(5, Vec3(float(s))), kEps);
    const double less = s * s * (2.0 / 3.0) * (1.0 / (1.0 + kEps) + 1.0 / (4.0 + kEps) + 1.0 / (9.0 + kEps)) / 5.0;
    CHECK(g.relMSE == Approx(f.relMSE - less).epsilon(1e-9));
}

TEST_CASE("particleMeanFloor: a particle of one true light in a noisy reference has none, 99.99% bounds", "[analysis][anatomy][statistical]") {
    // 20000 particles of k = 5 pixels each, every pixel's true Lr its
    // particle's (1), the reference r = 1 + e with e ~ N(0, s^2) and s
    // known. d = mean - r has variance q = s^2 (1 - 1/k), which the floor
    // takes away, so it is 0 up to the weight's own noise: w(r) = 1 / (r^2 +
    // eps) = w0 - 2 w0^2 e + c e^2 + ..., c = 4 w0^3 - w0^2, leaves c (E[d^2
    // e^2] - q s^2) in expectation, E[d^2 e^2] = s^4 ((k - 1) / k^2 + 3 (1 -
    // 1/k)^2) (Gaussian moments): 3.7 s^4 here, 4 standard errors. Each
    // term's variance is 2 q^2 w0^2, a particle's k terms correlated through
    // its mean (each pair's covariance 2 (s^2 / k)^2 w0^2): the bound counts
    // particles, a sum of k terms each, at 3.9 standard errors (99.99%).
    // Without the correction the floor is q w0 + c E[d^2 e^2].
    const std::size_t particles = 20000, k = 5;
    const double s = 0.05, w0 = 1.0 / (1.0 + kEps), q = s * s * (1.0 - 1.0 / k), c = 4.0 * w0 * w0 * w0 - w0 * w0;
    const double d2e2 = s * s * s * s * ((k - 1.0) / (k * k) + 3.0 * (1.0 - 1.0 / k) * (1.0 - 1.0 / k));
    std::mt19937_64 rng(5);
    std::normal_distribution<double> g(0.0, s);
    std::vector<Vec3> ref, stderr;
    std::vector<std::uint32_t> ids;
    for (std::size_t i = 0; i < particles; ++i)
        for (std::size_t j = 0; j < k; ++j) {
            ref.push_back(Vec3(float(1.0 + g(rng)), float(1.0 + g(rng)), float(1.0 + g(rng))));
            stderr.push_back(Vec3(float(s)));
            ids.push_back(std::uint32_t(i));
        }
    const ParticleMeanFloor f = particleMeanFloor(ref, ids, stderr, kEps);
    const ParticleMeanFloor raw = particleMeanFloor(ref, ids, {}, kEps);
    const double n = 3.0 * particles * k;
    const double perGroup = k * 2.0 * q * q * w0 * w0 + k * (k - 1.0) * 2.0 * (s * s / k) * (s * s / k) * w0 * w0;
    const double sd = std::sqrt(3.0 * particles * perGroup) / n;
    INFO("floor " << f.relMSE << ", uncorrected " << raw.relMSE << ", sd " << sd);
    CHECK(std::fabs(f.relMSE - c * (d2e2 - q * s * s)) < 3.9 * sd);
    CHECK(std::fabs(raw.relMSE - (q * w0 + c * d2e2)) < 3.9 * sd);
    CHECK(q * w0 > 50.0 * sd);
    CHECK(f.medianPixels == double(k));
}
