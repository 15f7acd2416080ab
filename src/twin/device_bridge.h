#pragma once
// The twin's bridge of the shared pass bodies (accretion/render/restir_passes.h):
// the launch's buffers, nothing counted, the reservoirs stored as they are.
#include "accretion/render/restir_passes.h"
#include "launch_params.h"
#include "restir_device.h"

namespace accretion::twin {

/// The ReuseParams of a launch.
__device__ inline restir::ReuseParams reuseParams(const RestirParams& rp) {
    restir::ReuseParams p;
    p.frame = rp.frame;
    p.seed = rp.seed;
    p.width = rp.width;
    p.height = rp.height;
    p.scale = rp.scale;
    p.normalThreshold = rp.normalThreshold;
    p.depthThreshold = rp.depthThreshold;
    p.mCap = rp.mCap;
    p.neighbours = rp.neighbours;
    p.radius = rp.radius;
    return p;
}

/// One thread's bridge: the launch's lighting grid, its reservoirs in and
/// out, and last frame's (prevLights, prevGbuffer, prevReservoirs).
template <ShadingModel SM>
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
            return restir::combineReservoirs(DeviceDomains<SM>{offers_, n_}, b_.p_.restir.bias, rng);
        }

    private:
        const DeviceBridge& b_;
        Offer offers_[N];
        std::uint32_t n_ = 0;
    };

    __device__ DeviceBridge(const LaunchParams& p, const restir::ReuseParams& params) : p_(p), params_(params) {}

    __device__ const restir::ReuseParams& params() const { return params_; }
    __device__ GBufferTexel texel(std::size_t px) const { return p_.restir.gbuffer[px]; }
    __device__ StoredReservoir input(std::size_t px) const { return p_.restir.in[px]; }
    __device__ void output(std::size_t px, const StoredReservoir& r) const { p_.restir.out[px] = r; }
    __device__ void store(std::size_t px, const StoredReservoir& r) const { p_.restir.out[px] = sanitize(p_.restir, r, px); }
    __device__ restir::NoRecorder recorder(std::size_t, const GBufferTexel&) const { return {}; }
    __device__ std::uint32_t reservoirBytes() const { return sizeof(StoredReservoir); }
    __device__ void reuse(bool) const {}
    template <std::uint32_t N>
    __device__ Offers<N> offers() const { return Offers<N>(*this); }

    __device__ bool historyHas(std::uint32_t j) const { return j < p_.restir.prevLights.count; }
    __device__ Vec3 historyPosition(std::uint32_t j) const { return p_.restir.prevLights.position[j]; }
    __device__ const Camera& historyCamera() const { return p_.restir.prevCamera; }
    __device__ GBufferTexel historyTexel(std::size_t q) const { return p_.restir.prevGbuffer[q]; }
    __device__ StoredReservoir historyReservoir(std::size_t q) const { return p_.restir.prevReservoirs[q]; }

private:
    const LaunchParams& p_;
    const restir::ReuseParams& params_;
};

}  // namespace accretion::twin
