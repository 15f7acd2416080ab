// relMSE's anatomy over seeds, and the floor of one value per particle.
#include "accretion/analysis/error_anatomy.h"

#include <algorithm>
#include <unordered_map>

#include "accretion/core/error.h"
#include "accretion/core/gbuffer_texel_layout.h"

namespace accretion {

std::vector<ErrorAnatomy> splitRelMseByGroup(const std::vector<DVec3>& sum, const std::vector<DVec3>& sumSq, double seeds,
                                             const std::vector<Vec3>& ref, const std::vector<Vec3>& refStderr, double eps,
                                             const std::vector<std::uint32_t>& group, std::uint32_t groups) {
    ACC_CHECK(seeds >= 2.0 && sum.size() == ref.size() && sumSq.size() == ref.size() && group.size() == ref.size());
    ACC_CHECK(refStderr.empty() || refStderr.size() == ref.size());
    std::vector<ErrorAnatomy> a(groups);
    if (ref.empty()) return a;
    for (std::size_t p = 0; p < ref.size(); ++p) {
        ACC_CHECK(group[p] < groups);
        ErrorAnatomy& g = a[group[p]];
        for (int c = 0; c < 3; ++c) {
            const double w = 1.0 / (double(ref[p][c]) * ref[p][c] + eps);
            const double m = sum[p][c] / seeds;
            const double v = std::max(0.0, (sumSq[p][c] / seeds - m * m) * seeds / (seeds - 1.0));
            const double s = refStderr.empty() ? 0.0 : double(refStderr[p][c]);
            g.noise += v * w;
            g.persistent += (m * m - v / seeds - s * s) * w;
        }
    }
    const double n = 3.0 * double(ref.size());
    for (ErrorAnatomy& g : a) {
        g.noise /= n;
        g.persistent /= n;
    }
    return a;
}

ErrorAnatomy splitRelMse(const std::vector<DVec3>& sum, const std::vector<DVec3>& sumSq, double seeds,
                         const std::vector<Vec3>& ref, const std::vector<Vec3>& refStderr, double eps) {
    return splitRelMseByGroup(sum, sumSq, seeds, ref, refStderr, eps, std::vector<std::uint32_t>(ref.size(), 0u), 1)[0];
}

std::unordered_map<std::uint32_t, ParticlePixels> particlePixels(const std::vector<Vec3>& light, const std::vector<std::uint32_t>& ids) {
    ACC_CHECK(ids.size() == light.size());
    std::unordered_map<std::uint32_t, ParticlePixels> out;
    for (std::size_t p = 0; p < light.size(); ++p)
        if (ids[p] != kNoParticle) {
            ParticlePixels& m = out[ids[p]];
            m.sum += DVec3(light[p]);
            ++m.pixels;
        }
    return out;
}

ParticleMeanFloor particleMeanFloor(const std::vector<Vec3>& ref, const std::vector<std::uint32_t>& ids,
                                    const std::vector<Vec3>& refStderr, double eps) {
    ACC_CHECK(ids.size() == ref.size() && (refStderr.empty() || refStderr.size() == ref.size()));
    const std::unordered_map<std::uint32_t, ParticlePixels> means = particlePixels(ref, ids);
    ParticleMeanFloor f;
    f.particles = means.size();
    if (ref.empty()) return f;
    double rel = 0.0;
    for (std::size_t p = 0; p < ref.size(); ++p) {
        if (ids[p] == kNoParticle) continue;
        const ParticlePixels& m = means.at(ids[p]);
        const double k = double(m.pixels);
        for (int c = 0; c < 3; ++c) {
            const double r = ref[p][c], d = m.sum[c] / k - r;
            // The reference's noise adds sigma^2 (1 - 1/k) to d^2 in
            // expectation where the particle's k pixels share one sigma:
            // sigma^2 (1 - 1/k)^2 of this pixel's, sigma^2 (k - 1) / k^2 of
            // the others'.
            const double s = refStderr.empty() ? 0.0 : double(refStderr[p][c]);
            rel += (d * d - s * s * (1.0 - 1.0 / k)) / (r * r + eps);
        }
    }
    f.relMSE = rel / (3.0 * double(ref.size()));
    std::vector<std::size_t> sizes;
    sizes.reserve(means.size());
    for (const auto& [id, m] : means) sizes.push_back(m.pixels);
    if (!sizes.empty()) {
        const std::size_t h = sizes.size() / 2;
        std::nth_element(sizes.begin(), sizes.begin() + h, sizes.end());
        f.medianPixels = double(sizes[h]);
        if (sizes.size() % 2 == 0) f.medianPixels = 0.5 * (f.medianPixels + double(*std::max_element(sizes.begin(), sizes.begin() + h)));
    }
    return f;
}

}  // namespace accretion
