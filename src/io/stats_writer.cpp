#include "accretion/io/stats_writer.h"

namespace accretion {

nlohmann::json windowsJson(const std::vector<PixelWindow>& windows) {
    nlohmann::json j = nlohmann::json::array();
    for (const PixelWindow& w : windows) j.push_back({w.x0, w.x1, w.y0, w.y1});
    return j;
}

nlohmann::json reuseCountsJson(const ReuseCounts& c) {
    nlohmann::json outcomes = nlohmann::json::object();
    for (std::size_t k = 0; k < kReuseOutcomes; ++k) outcomes[std::string(kReuseOutcomeNames[k])] = c.n[k];
    return {{"offered", c.offered()}, {"accepted", c.accepted()}, {"m_capped", c.mCapped}, {"outcomes", outcomes}};
}

nlohmann::json frameStatsJson(const FrameStats& s) {
    nlohmann::json passes = nlohmann::json::object();
    for (const auto& [pass, seconds] : s.timer.all()) passes[std::string(passName(pass))] = seconds;
    nlohmann::json nonFinite = nlohmann::json::object();
    for (const auto& [pass, count] : s.nonFinite) nonFinite[std::string(passName(pass))] = count;
    const double lightingSeconds = s.timer.seconds(Pass::estimateLighting);
    nlohmann::json reuse = nlohmann::json::object();
    for (const auto& [pass, counts] : s.reuse) reuse[std::string(passName(pass))] = reuseCountsJson(counts);

    nlohmann::json j = {
        {"frame", s.frame},
        {"origin", {s.origin.x, s.origin.y, s.origin.z}},  // world position of the frame coordinates' origin
        {"seconds", s.seconds},
        {"passes", passes},
        {"counts",
         {{"particles", s.particles},
          {"clusters", s.bvh.clusters},
          {"primitives", s.bvh.primitives},
          {"triangles", s.bvh.triangles},
          {"hit_pixels", s.hitPixels},
          {"light_terms", s.lighting.lightTerms},
          {"reuse_accepted", s.lighting.reuse.accepted()},
          {"reuse_rejected", s.lighting.reuse.offered() - s.lighting.reuse.accepted()},
          {"nonfinite_rejected", nonFinite},
          {"reuse", reuse},
          {"light_tree_nodes", s.lightTreeNodes},
          {"near_lights", s.nearLights.k},
          {"reservoir_bytes", s.reservoirBytes},
          {"mean_spp", s.meanSpp},
          {"max_spp", s.maxSpp}}},
        {"rays",
         {{"primary", s.primaryRays},
          {"shadow", s.lighting.shadowRays},
          {"shadow_occluded", s.lighting.shadowOccluded},
          {"shadow_per_second", lightingSeconds > 0 ? double(s.lighting.shadowRays) / lightingSeconds : 0.0}}},
        {"bvh",
         {{"layout", s.bvh.layout},
          {"built", s.bvh.built},
          {"reclustered", s.bvh.reclustered},
          {"refitted", s.bvh.refitted},
          {"partial", s.bvh.partial},
          {"rebuilt_clusters", s.bvh.rebuiltClusters},
          {"cluster_seconds", s.bvh.clusterSeconds},
          {"blas_seconds", s.bvh.blasSeconds},
          {"tlas_seconds", s.bvh.tlasSeconds},
          {"embree_bytes", s.bvh.embreeBytes}}},
    };
    if (!s.nearLights.candidates.empty()) {  // split, k automatic: the pilot's table (docs/MODEL.md section 4)
        nlohmann::json rows = nlohmann::json::array();
        for (const NearLightChoice::Candidate& c : s.nearLights.candidates)
            rows.push_back({{"k", c.k}, {"rel_variance", c.relVariance}, {"cost", c.cost}, {"rel_variance_x_cost", c.relVariance * c.cost}});
        j["near_light_pilot"] = {{"k", s.nearLights.k}, {"pixels", s.nearLights.pixels},
                                 {"far_sample_cost", NearLightChoice::kFarSampleCost}, {"candidates", rows}};
    }
    return j;
}

}  // namespace accretion
