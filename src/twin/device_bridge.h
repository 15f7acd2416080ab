#pragma once
// The twin's bridge of the shared pass bodies (accretion/render/restir_passes.h):
// the launch's buffers, nothing counted, the reservoirs stored as they are.
#include "accretion/render/particle_restir_passes.h"
#include "launch_params.h"
#include "restir_device.h"

namespace accretion::twin {

/// The visibility of a bridge whose pass traces no shadow ray (the twin
/// refuses restir.candidate_visibility: generateCandidates never asks).
struct NoShadowRays {
    __device__ bool operator()(const ShadingPoint&, std::uint32_t, const LightTerm&) const { return true; }
};

/// render.source on the twin: the light tree at the receiver, else the
/// source pmf (uniform or power; the twin refuses tiles and regir). Nothing
/// counted.
struct DeviceSource {
    const LaunchParams& p;
    struct Drawer {
        const LaunchParams& p;
        const ShadingPoint& sp;
        __device__ LightSample sample(PortableRng& g) const { return p.tree.nodes ? p.tree.sample(sp, g) : p.source.sample(g); }
    };
    __device__ std::uint32_t reads() const { return 0; }
    __device__ std::uint32_t gathers() const { return 0; }
    __device__ Drawer at(const ShadingPoint& sp, std::uint32_t, std::uint32_t, PortableRng&) const { return {p, sp}; }
};

/// One thread's bridge: the launch's lighting grid, its reservoirs in and
/// out (restir.in and restir.out, or restir.out in place), last frame's
/// (prevLights, prevGbuffer, prevReservoirs), and the pass's shadow rays
/// (Visibility: sp, light, term -> seen, counted by the raygen).
template <ShadingModel SM, class Visibility = NoShadowRays>
class DeviceBridge {
public:
    using Rng = PortableRng;

    /// Up to N offers in the thread's local memory, combined by restir_steps.h.
    template <std::uint32_t N>
    class Offers {
    public:
        __device__ explicit Offers(const DeviceBridge& b) : b_(b) {}
        __device__ void addCurrent(const StoredReservoir& r, const GBufferTexel& g) {
            offers_[n_++] = {r, shadingPointOf(g, b_.p_.lights), &b_.p_.lights};
        }
        __device__ void addHistory(const StoredReservoir& r, std::size_t q) {
            const RestirParams& rp = b_.p_.restir;
            offers_[n_++] = {r, shadingPointOf(rp.prevGbuffer[q], rp.prevLights), &rp.prevLights};
        }
        __device__ StoredReservoir combine(PortableRng& rng) const {
            // A full list of a few (temporal's 2) is combined with its size a
            // constant: combineReservoirs' loops unroll and the offers stay in
            // registers (with the count a variable, temporalResampling at
            // 1080p took 2.6x its time on the H200).
            if constexpr (N <= 2)
                if (n_ == N) return restir::combineReservoirs(DeviceDomains<SM>{offers_, N}, b_.p_.restir.bias, rng);
            return restir::combineReservoirs(DeviceDomains<SM>{offers_, n_}, b_.p_.restir.bias, rng);
        }

    private:
        const DeviceBridge& b_;
        Offer offers_[N];
        std::uint32_t n_ = 0;
    };

    __device__ explicit DeviceBridge(const LaunchParams& p, bool inPlace = false, Visibility visibility = {},
                                     LaunchCounters* counters = nullptr)
        : p_(p), in_(inPlace ? p.restir.out : p.restir.in), visibility_(visibility), counters_(counters) {}

    __device__ const restir::ReuseParams& params() const { return p_.restir.reuse; }
    __device__ GBufferTexel texel(std::size_t px) const { return p_.restir.gbuffer[px]; }
    __device__ StoredReservoir input(std::size_t px) const { return in_[px]; }
    __device__ void output(std::size_t px, const StoredReservoir& r) const { p_.restir.out[px] = r; }
    __device__ void keep(std::size_t px, const StoredReservoir& r) const { p_.restir.out[px] = r; }
    __device__ bool reject(std::size_t px) const { return rejectAt(p_.restir, px); }
    __device__ restir::NoRecorder recorder(std::size_t, const GBufferTexel&) const { return {}; }
    __device__ std::uint32_t reservoirBytes() const { return sizeof(StoredReservoir); }
    __device__ void reuse(ReuseOutcome) const {}
    __device__ void historyCapped() const {}
    template <std::uint32_t N>
    __device__ Offers<N> offers() const { return Offers<N>(*this); }

    __device__ bool historyHas(std::uint32_t j) const { return j < p_.restir.prevLights.count; }
    __device__ Vec3 historyPosition(std::uint32_t j) const { return p_.restir.prevLights.position[j]; }
    __device__ const Camera& historyCamera() const { return p_.restir.prevCamera; }
    __device__ GBufferTexel historyTexel(std::size_t q) const { return p_.restir.prevGbuffer[q]; }
    __device__ StoredReservoir historyReservoir(std::size_t q) const { return p_.restir.prevReservoirs[q]; }

    __device__ ShadingPoint shadingPoint(const GBufferTexel& g) const { return shadingPointOf(g, p_.lights); }
    __device__ float targetPdf(const ShadingPoint& sp, std::uint32_t i) const { return twin::targetPdf<SM>(p_.lights, sp, i); }
    __device__ bool lightTerm(const ShadingPoint& sp, std::uint32_t i, LightTerm& t) const {
        return twin::lightTerm<SM>(p_.lights, sp, i, t);
    }
    __device__ void countLightTerm() const {
        if (counters_) ++counters_->lightTerms;
    }
    __device__ bool shadows() const { return p_.shadows; }
    __device__ bool visible(const ShadingPoint& sp, std::uint32_t i, const LightTerm& t, restir::NoRecorder&) const {
        return visibility_(sp, i, t);
    }
    __device__ void occluded() const {}  // the raygen's visibility counts its blocked rays
    __device__ bool dropOccludedCandidates() const { return false; }
    __device__ bool visibilityReuse() const { return p_.restir.visibilityReuse; }
    __device__ void writeLr(std::size_t px, const Vec3& Lr) const { p_.restir.Lr[px] = Lr; }

    // particle_restir (particle_restir_passes.h).
    __device__ bool historyTexelOf(std::uint32_t j, std::uint32_t sub, std::size_t& q) const {
        const RestirParams& rp = p_.restir;
        if (j >= rp.prevSlotCount || rp.prevSlotOf[j] == kNoSlot) return false;
        q = std::size_t(rp.prevSlotOf[j]) * rp.reuse.texelsPerParticle() + sub;
        return true;
    }
    __device__ GBufferTexel pixel(std::size_t px) const { return p_.gbuffer[px]; }
    __device__ std::uint32_t slotOf(std::uint32_t j) const { return p_.restir.slotOf[j]; }
    __device__ Vec2 pixelUv(const GBufferTexel& g) const {
        return billboardUv(g.local, p_.radius[g.particle], p_.frames[g.particle]);
    }
    __device__ GBufferTexel gridTexel(std::size_t q) const { return p_.restir.gbuffer[q]; }
    __device__ StoredReservoir gridReservoir(std::size_t q) const { return in_[q]; }
    __device__ Vec3 gridLr(std::size_t q) const { return p_.restir.Lr[q]; }
    __device__ Vec3 historyLr(std::size_t q) const { return p_.restir.prevTexelLr[q]; }
    __device__ void writePixelLr(std::size_t px, const Vec3& Lr) const { p_.Lr[px] = Lr; }
    __device__ std::uint32_t clusterOf(std::uint32_t i) const { return p_.restir.particleCluster[i]; }

private:
    const LaunchParams& p_;
    const StoredReservoir* in_;
    Visibility visibility_;
    LaunchCounters* counters_;
};

}  // namespace accretion::twin
