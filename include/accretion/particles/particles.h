#pragma once
#include <cstdint>
#include <vector>

#include "accretion/core/math.h"

namespace accretion {

/// The particle buffer of one frame, struct-of-arrays (docs/MODEL.md section 1).
struct Particles {
    std::vector<Vec3> position;      ///< p_i, centre
    std::vector<float> radius;       ///< r_i > 0
    std::vector<Vec3> emission;      ///< I_i, RGB point intensity
    std::vector<float> opacity;      ///< a_i in [0,1] (carried, not used by shading)
    std::vector<Vec3> albedo;        ///< rho_i
    std::vector<std::uint8_t> type;  ///< the "material" a hit shader switches on
    std::vector<Vec3> velocity;      ///< v_i, per unit time

    std::size_t size() const { return position.size(); }
    bool empty() const { return position.empty(); }
    void resize(std::size_t n) {
        position.resize(n);
        radius.resize(n);
        emission.resize(n);
        opacity.resize(n, 1.0f);
        albedo.resize(n);
        type.resize(n, 0);
        velocity.resize(n, Vec3(0.0f));
    }
    /// Append one particle (tests and small scenes).
    void push(const Vec3& p, float r, const Vec3& I, const Vec3& rho = Vec3(0.8f), std::uint8_t t = 0,
              const Vec3& v = Vec3(0.0f), float a = 1.0f) {
        position.push_back(p);
        radius.push_back(r);
        emission.push_back(I);
        opacity.push_back(a);
        albedo.push_back(rho);
        type.push_back(t);
        velocity.push_back(v);
    }
};

}  // namespace accretion
