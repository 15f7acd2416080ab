#pragma once
#include <cmath>
#include <concepts>
#include <cstdint>

#include <glm/glm.hpp>

/// Functions the OptiX twin (src/twin) shares with the CPU renderer: host and
/// device under nvcc, plain inline functions otherwise. The twin compiles them
/// without FMA contraction, so both sides round every operation alike.
#if defined(__CUDACC__)
#define ACC_HD __host__ __device__
/// A shared per-pixel body: inlined into its kernel, so that its bridge and
/// buffers stay in registers (a call passes them through local memory).
#define ACC_HD_BODY __host__ __device__ __forceinline__
#else
#define ACC_HD
#define ACC_HD_BODY inline
#endif

namespace accretion {

using Vec2 = glm::vec2;
using Vec3 = glm::vec3;
using DVec3 = glm::dvec3;

inline constexpr float kPi = 3.14159265358979323846f;
inline constexpr float kInvPi = 1.0f / kPi;
inline constexpr float kInv4Pi = 1.0f / (4.0f * kPi);

/// Rec.709 / sRGB luminance of a linear RGB triple.
ACC_HD inline float luminance(const Vec3& c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

/// Bits that address n items, indices 0..n-1 (at least 1): 100K particles need 17.
inline std::uint32_t indexBits(std::uint64_t n) {
    std::uint32_t b = 1;
    while (b < 64 && (std::uint64_t(1) << b) < n) ++b;
    return b;
}

inline bool isFinite(const Vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

/// std::isfinite on the host, CUDA's isfinite on the device (float stays
/// float: no widening per candidate).
template <std::floating_point T>
ACC_HD inline bool isFiniteNumber(T x) {
#if defined(__CUDA_ARCH__)
    return isfinite(x);
#else
    return std::isfinite(x);
#endif
}

/// Orthonormal basis around a unit vector n (Duff et al. 2017, branchless).
inline void orthonormalBasis(const Vec3& n, Vec3& t, Vec3& b) {
    const float sign = std::copysign(1.0f, n.z);
    const float a = -1.0f / (sign + n.z);
    const float c = n.x * n.y * a;
    t = Vec3(1.0f + sign * n.x * n.x * a, sign * c, -sign * n.x);
    b = Vec3(c, sign + n.y * n.y * a, -n.y);
}

}  // namespace accretion
