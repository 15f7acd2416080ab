// Pass names: every pass's name reads back as that pass, a repeated run's
// name as its pass, and nothing else reads as a pass.
#include <catch2/catch.hpp>

#include <iterator>
#include <utility>

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

TEST_CASE("each pass has its own name, spelled as the stats files and the GPU timings spell it", "[core]") {
    // Written out here, not taken from the table: a reordered enum or name list fails.
    const std::pair<Pass, const char*> spelled[] = {
        {Pass::loadParticles, "loadParticles"},           {Pass::buildLightSampler, "buildLightSampler"},
        {Pass::chooseNearLights, "chooseNearLights"},
        {Pass::buildClusters, "buildClusters"},           {Pass::traceGBuffer, "traceGBuffer"},
        {Pass::estimateLighting, "estimateLighting"},     {Pass::presampleLightTiles, "presampleLightTiles"},
        {Pass::presampleRegirGrid, "presampleRegirGrid"}, {Pass::generateCandidates, "generateCandidates"},
        {Pass::temporalResampling, "temporalResampling"}, {Pass::spatialResampling, "spatialResampling"},
        {Pass::traceShadowRays, "traceShadowRays"},       {Pass::upsampleLighting, "upsampleLighting"},
        {Pass::composeImage, "composeImage"},             {Pass::writeOutputs, "writeOutputs"}};
    REQUIRE(std::size(spelled) == kPassNames.size());
    for (const auto& [p, name] : spelled) CHECK(passName(p) == name);
    CHECK(pass::traceShadowRays == "traceShadowRays");
}
