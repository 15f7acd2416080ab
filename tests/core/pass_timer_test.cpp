// Pass names: every pass's name reads back as that pass, a repeated run's
// name as its pass, and nothing else reads as a pass.
#include <catch2/catch.hpp>

#include "accretion/core/pass_timer.h"

using namespace accretion;

TEST_CASE("parsePass reads every pass name back, and refuses other names", "[core]") {
    for (std::size_t k = 0; k < kPassNames.size(); ++k) {
        const Pass p = static_cast<Pass>(k);
        REQUIRE(parsePass(passName(p)) == p);
        REQUIRE(parsePass(std::string(passName(p)) + "[2]") == p);
    }
    CHECK(parsePass("spatialResampling[12]") == Pass::spatialResampling);
    for (const char* bad : {"", "traceShadowRay", "TraceShadowRays", "spatialResampling[]", "spatialResampling[0]",
                            "spatialResampling[2", "spatialResampling[x]", "spatialResampling[2]x", "buildBlas"})
        CHECK_FALSE(parsePass(bad).has_value());
}

TEST_CASE("the pass constants are the enum's names", "[core]") {
    CHECK(pass::traceShadowRays == passName(Pass::traceShadowRays));
    CHECK(pass::loadParticles == kPassNames.front());
    CHECK(pass::writeOutputs == kPassNames.back());
}
