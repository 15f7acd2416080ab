#pragma once
// The twin's bridge of particle_split's pass bodies
// (accretion/render/particle_split_passes.h): the launch's texels and near
// lights, the light tree, OptiX shadow rays (Visibility: sp, light, term ->
// seen, counted by the raygen), nothing else counted.
#include "accretion/render/particle_split_passes.h"
#include "launch_params.h"
#include "restir_device.h"

namespace accretion::twin {

/// The visibility of a pass that traces no shadow ray.
struct NoSplitRays {
    __device__ bool operator()(const ShadingPoint&, std::uint32_t, const LightTerm&) const { return true; }
};

template <ShadingModel SM, class Visibility = NoSplitRays>
class SplitBridge {
public:
    __device__ SplitBridge(const LaunchParams& p, Visibility visibility = {}, LaunchCounters* counters = nullptr)
        : p_(p), s_(p.split), visibility_(visibility), counters_(counters) {}

    __device__ const psplit::SplitParams& params() const { return s_.params; }

    // findNearLights
    __device__ std::uint32_t particleOfSlot(std::uint32_t v) const { return s_.particleOf[v]; }
    __device__ Vec3 particlePosition(std::uint32_t j) const { return p_.position[j]; }
    __device__ std::uint64_t lightPath(std::uint32_t j) const { return s_.lightPath[j]; }
    __device__ const LightTreeView& tree() const { return p_.tree; }
    __device__ void writeNear(std::uint32_t v, const std::uint32_t* light, std::uint32_t count, float radius2) const {
        std::uint32_t* out = s_.near + std::size_t(v) * s_.params.nearCount;
        for (std::uint32_t m = 0; m < s_.params.nearCount; ++m) out[m] = m < count ? light[m] : psplit::kNoNearLight;
        s_.nearFound[v] = count;
        s_.nearRadius2[v] = radius2;
    }

    // shadeSplitTexels
    __device__ GBufferTexel texel(std::size_t q) const { return s_.texels[q]; }
    __device__ ShadingPoint shadingPoint(const GBufferTexel& g) const { return shadingPointOf(g, p_.lights); }
    __device__ std::uint32_t nearLight(std::uint32_t v, std::uint32_t m) const {
        return s_.near[std::size_t(v) * s_.params.nearCount + m];
    }
    __device__ std::uint32_t nearLights(std::uint32_t v, std::uint32_t* light) const {
        const std::uint32_t n = s_.nearFound[v];
        const std::uint32_t* in = s_.near + std::size_t(v) * s_.params.nearCount;
        for (std::uint32_t m = 0; m < n; ++m) light[m] = in[m];
        return n;
    }
    __device__ float nearRadius2(std::uint32_t v) const { return s_.nearRadius2[v]; }
    /// The ray the launch of traceSplitRays traced (sumSplitTexel sums them).
    __device__ psplit::SplitRay splitRay(std::size_t q, std::uint32_t r) const {
        return s_.rays[std::size_t(r) * s_.rayStride + q];
    }
    __device__ LightSample sampleFar(const ShadingPoint& sp, PortableRng& rng, const psplit::FarImportance& importance) const {
        return p_.tree.sample(sp, rng, importance);
    }
    __device__ bool term(const ShadingPoint& sp, std::uint32_t i, LightTerm& t) const {
        if (counters_) ++counters_->lightTerms;
        const LightView& L = p_.lights;
        if (i >= L.count) return false;
        return evalLight<SM>(sp, L.position[i], L.emission[i], L.dmin2[i], t);
    }
    __device__ bool shadows() const { return p_.shadows; }
    __device__ bool visible(const ShadingPoint& sp, std::uint32_t i, const LightTerm& t) const { return visibility_(sp, i, t); }
    __device__ void reject(std::size_t q) const { ++s_.rejected[q]; }  // one thread a texel
    __device__ bool historyTexelOf(std::uint32_t j, std::uint32_t sub, std::size_t& q) const {
        if (j >= s_.prevSlotCount || s_.prevSlotOf[j] == kNoSlot) return false;
        q = std::size_t(s_.prevSlotOf[j]) * s_.params.texelsPerParticle() + sub;
        return true;
    }
    __device__ Vec3 historyLr(std::size_t q) const { return s_.prevTexelLr[q]; }
    __device__ void writeTexelLr(std::size_t q, const Vec3& Lr) const { s_.texelLr[q] = Lr; }
    __device__ Vec3 historyFar(std::size_t q) const { return s_.prevTexelFar[q]; }
    __device__ void writeTexelFar(std::size_t q, const Vec3& far) const { s_.texelFar[q] = far; }
    __device__ std::uint32_t historyAge(std::size_t q) const { return s_.prevTexelAge[q]; }
    __device__ std::uint32_t historyNearLights(std::uint32_t v, std::uint32_t* light) const {
        const std::uint32_t n = s_.prevNearFound[v];
        const std::uint32_t* in = s_.prevNear + std::size_t(v) * s_.params.nearCount;
        for (std::uint32_t m = 0; m < n; ++m) light[m] = in[m];
        return n;
    }
    __device__ Vec3 historyNearValue(std::size_t q, std::uint32_t m) const { return s_.prevTexelNear[q * s_.params.nearCount + m]; }
    __device__ void writeTexelNear(std::size_t q, std::uint32_t m, const Vec3& v) const { s_.texelNear[q * s_.params.nearCount + m] = v; }
    __device__ void writeTexelAge(std::size_t q, std::uint32_t n) const { s_.texelAge[q] = n; }

    // shadeParticlePixels
    __device__ GBufferTexel pixel(std::size_t px) const { return p_.gbuffer[px]; }
    __device__ std::uint32_t slotOf(std::uint32_t j) const { return s_.slotOf[j]; }
    __device__ Vec2 pixelUv(const GBufferTexel& g) const {
        return billboardUv(g.local, p_.radius[g.particle], p_.frames[g.particle]);
    }
    __device__ Vec3 texelLr(std::size_t q) const { return s_.texelLr[q]; }
    __device__ void writePixelLr(std::size_t px, const Vec3& Lr) const { p_.Lr[px] = Lr; }

private:
    const LaunchParams& p_;
    const SplitLaunch& s_;
    Visibility visibility_;
    LaunchCounters* counters_;
};

}  // namespace accretion::twin
