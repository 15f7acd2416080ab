// The shared ReSTIR steps (accretion/render/restir_steps.h) compiled both
// ways: scripts/compile_twin.sh builds this file with g++ and with nvcc (as
// CUDA, where the steps are __host__ __device__ and CUDA's headers are in
// play) and requires the two programs to print the same bits. Every step
// runs on inputs drawn from a fixed stream; each result is printed as hex.
#include <cstdio>
#include <cstring>

#include "accretion/core/rng.h"
#include "accretion/render/restir_steps.h"

namespace {

using namespace accretion;

unsigned bits(float v) {
    unsigned u;
    std::memcpy(&u, &v, sizeof u);
    return u;
}

/// Domains whose p_hat is a fixed function of (domain, light): zero for a
/// few pairs, so basic's support and pairwise's zero branches are taken.
struct TableDomains {
    StoredReservoir r[restir::kMaxOffers];
    std::uint32_t n;
    std::uint32_t terms = 0;
    std::uint32_t count() const { return n; }
    const StoredReservoir& reservoir(std::uint32_t i) const { return r[i]; }
    float targetPdf(std::uint32_t i, std::uint32_t y) const {
        const std::uint32_t h = (i * 2654435761u) ^ (y * 40503u);
        return h % 7 == 0 ? 0.0f : float(h % 1000 + 1) * 0.001f;
    }
    bool supports(std::uint32_t i, std::uint32_t y) const { return targetPdf(i, y) > 0.0f; }
    void countTerm() const {}
};

}  // namespace

int main() {
    PortableRng in(7, 3, RngPass::restirSpatial, 11);  // the inputs
    // drawNeighbour over grids and radii.
    for (int k = 0; k < 2000; ++k) {
        PortableRng rng(std::uint64_t(k), 1, RngPass::restirSpatial, 5);
        const std::uint32_t W = 64 + k % 7, H = 36 + k % 5, x = k % W, y = (k / 3) % H;
        std::size_t q = 0;
        const bool ok = restir::drawNeighbour(rng, 1.0f + float(k % 40), x, y, W, H, q);
        std::printf("n %d %zu\n", int(ok), ok ? q : 0);
    }
    // reprojectPoint through a camera.
    const Camera cam = Camera::lookAt(Vec3(0.0f, 7.0f, 17.0f), Vec3(0.0f), Vec3(0.0f, 1.0f, 0.0f), 45.0, 320, 180);
    for (int k = 0; k < 2000; ++k) {
        const Vec3 p(20.0f * in.uniform() - 10.0f, 2.0f * in.uniform() - 1.0f, 20.0f * in.uniform() - 10.0f);
        std::size_t q = 0;
        float depth = 0.0f;
        const bool ok = restir::reprojectPoint(cam, p, k % 2 ? 0.5f : 1.0f, k % 2 ? 160 : 320, k % 2 ? 90 : 180, q, depth);
        std::printf("p %d %zu %08x\n", int(ok), ok ? q : 0, ok ? bits(depth) : 0u);
    }
    // capHistoryM.
    for (std::uint32_t k = 0; k < 200; ++k) std::printf("m %u\n", restir::capHistoryM(k * 37u, k % 9, 0.5 + 0.25 * (k % 80)));
    // resampleCandidates, with the odd zero-pdf and non-finite candidate.
    for (int k = 0; k < 500; ++k) {
        PortableRng rng(std::uint64_t(k), 2, RngPass::restirCandidates, 3);
        int rejects = 0;
        const auto draw = [&](PortableRng& g) {
            const std::uint32_t i = static_cast<std::uint32_t>(g.uniform() * 1000.0f);
            return LightSample{i, i % 97 == 0 ? 0.0f : 0.001f};
        };
        const auto target = [&](std::uint32_t i) { return i % 211 == 0 ? 1e38f : float(i % 13) * 0.125f; };
        Reservoir r;
        const bool kept = restir::resampleCandidates(1 + k % 32, rng, draw, target, [&] { return ++rejects > 100; }, r);
        std::printf("c %d %d %u %08x %08x %08x %u\n", int(kept), rejects, r.y, bits(r.w_sum), bits(r.p_hat), bits(r.W), r.M);
    }
    // combineReservoirs under each bias correction.
    for (int k = 0; k < 1500; ++k) {
        TableDomains d{};
        d.n = 1 + std::uint32_t(k % restir::kMaxOffers);
        for (std::uint32_t i = 0; i < d.n; ++i) {
            const std::uint32_t y = static_cast<std::uint32_t>(in.uniform() * 5000.0f);
            const float W = in.uniform() < 0.1f ? 0.0f : 10.0f * in.uniform();
            d.r[i] = StoredReservoir{y, W, 1u + static_cast<std::uint32_t>(in.uniform() * 40.0f), d.targetPdf(i, y)};
        }
        const BiasCorrection bias = k % 3 == 0 ? BiasCorrection::none : k % 3 == 1 ? BiasCorrection::basic : BiasCorrection::pairwise;
        PortableRng rng(std::uint64_t(k), 4, RngPass::restirTemporal, 9);
        const StoredReservoir out = restir::combineReservoirs(d, bias, rng);
        std::printf("r %u %08x %u %08x\n", out.y, bits(out.W), out.M, bits(out.p_hat));
    }
    // shadeSample.
    for (int k = 0; k < 300; ++k) {
        LightTerm t{Vec3(in.uniform(), in.uniform(), k % 50 == 0 ? 3e38f : in.uniform()), Vec3(0.0f, 0.0f, 1.0f), 1.0f};
        Vec3 Lr(0.0f);
        const restir::Shade s = restir::shadeSample(t, 100.0f * in.uniform(), k % 4 != 0, Lr);
        std::printf("s %d %08x %08x %08x\n", int(s), bits(Lr.x), bits(Lr.y), bits(Lr.z));
    }
    return 0;
}
