// The cost model's fit: non-negative least squares recovers known
// coefficients from synthetic timings, exactly without noise and within a
// stated tolerance with noise; negative solutions are clamped.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <random>

#include "accretion/core/median.h"
#include "accretion/gpu/cost_model.h"
#include "support/test_scenes.h"

using namespace accretion;

namespace {

/// Pass-like feature rows: threads ~1e6, steps, rays, entries, any-hits, bytes of different scales.
std::vector<CostRow> syntheticRows(std::size_t n, std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<CostRow> rows;
    for (std::size_t i = 0; i < n; ++i) {
        CostRow r;
        r.config = "c" + std::to_string(i / 7);
        r.pass = {static_cast<Pass>(i % 7)};
        r.features = {1e6 * (0.2 + u(rng)), 5e4 * u(rng), 1e6 * u(rng), 4e6 * u(rng), 2e5 * u(rng), 8e7 * (0.1 + u(rng))};
        rows.push_back(r);
    }
    return rows;
}

}  // namespace

TEST_CASE("calibrate recovers known coefficients from exact synthetic timings", "[gpu][cost]") {
    CostCoefficients truth;
    truth.ns = {0.03, 0.7, 0.4, 0.15, 2.0, 0.0025};
    std::vector<CostRow> rows = syntheticRows(28, 1);
    for (CostRow& r : rows) r.measuredMs = truth.predictMs(r.features);
    const Calibration c = calibrate(rows);
    for (std::size_t k = 0; k < truth.ns.size(); ++k) {
        INFO(kCostFeatures[std::size_t(k)]);
        CHECK(c.coefficients.ns[k] == Approx(truth.ns[k]).epsilon(1e-6));
    }
    CHECK(c.r2 == Approx(1.0).margin(1e-9));
    CHECK(c.rmsMs < 1e-9);
}

TEST_CASE("calibrate with 2% timing noise stays within 10% and keeps a zero coefficient non-negative", "[gpu][cost]") {
    CostCoefficients truth;
    truth.ns = {0.03, 0.7, 0.4, 0.0, 2.0, 0.0025};  // BLAS entries cost nothing here
    std::vector<CostRow> rows = syntheticRows(140, 2);
    std::mt19937 rng(3);
    std::normal_distribution<double> noise(0.0, 0.02);
    for (CostRow& r : rows) r.measuredMs = truth.predictMs(r.features) * (1.0 + noise(rng));
    const Calibration c = calibrate(rows);
    for (double x : c.coefficients.ns) CHECK(x >= 0.0);
    // With 140 rows and 2% noise the standard error of each coefficient is
    // ~1% of the largest-scale terms; 10% leaves room for the smallest ones.
    for (const CostFeature k : {CostFeature::threads, CostFeature::warp_steps, CostFeature::rays, CostFeature::any_hits, CostFeature::bytes}) {
        INFO(kCostFeatures[std::size_t(k)]);
        CHECK(c.coefficients.ns[k] == Approx(truth.ns[k]).epsilon(0.10));
    }
    CHECK(c.coefficients.ns[CostFeature::blas_entries] < 0.02);
    CHECK(c.r2 > 0.99);
}

TEST_CASE("NNLS clamps what unconstrained least squares would make negative", "[gpu][cost]") {
    // b = 1*x0 - 1*x1 on independent columns: the unconstrained fit has x1 = -1.
    std::vector<CostFeatures> A;
    std::vector<double> b;
    for (int i = 0; i < 12; ++i) {
        CostFeatures f{};
        f[CostFeature::threads] = 1.0 + i;
        f[CostFeature::warp_steps] = (i % 3) + 0.5;
        f[CostFeature::rays] = (i % 2);
        f[CostFeature::blas_entries] = i * i * 0.1;
        f[CostFeature::any_hits] = (i % 5);
        f[CostFeature::bytes] = 1.0;
        A.push_back(f);
        b.push_back(f[CostFeature::threads] - f[CostFeature::warp_steps]);
    }
    const std::vector<double> x = nonNegativeLeastSquares(A, b);
    for (double v : x) CHECK(v >= 0.0);
    CHECK(x[1] == 0.0);
    // KKT: the gradient on the zero variables points outwards (A^T (b - A x) <= 0).
    for (std::size_t j = 0; j < x.size(); ++j) {
        if (x[j] > 0.0) continue;
        double g = 0.0;
        for (std::size_t i = 0; i < A.size(); ++i) {
            double r = b[i];
            for (std::size_t k = 0; k < x.size(); ++k) r -= A[i][k] * x[k];
            g += A[i][j] * r;
        }
        CHECK(g <= 1e-9);
    }
}

TEST_CASE("the per-pass form predicts held-out configurations its form made exactly, the shared form cannot", "[gpu][cost]") {
    // Two passes whose times the shared form cannot express: builds at a
    // constant per BLAS, traced rays whose cost grows with the BLAS depths.
    CostCoefficients truth;
    truth.perPass[Pass::buildClusters] = {};
    truth.perPass[Pass::buildClusters][CostFeature::dispatches] = 5000.0;
    truth.perPass[Pass::buildClusters][CostFeature::build_launches] = 75000.0;
    truth.perPass[Pass::traceShadowRays] = {};
    truth.perPass[Pass::traceShadowRays][CostFeature::rays] = 1.5;
    truth.perPass[Pass::traceShadowRays][CostFeature::blas_levels] = 0.03;
    truth.perPass[Pass::traceShadowRays][CostFeature::dispatches] = 10000.0;
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<CostRow> rows;
    for (int c = 0; c < 20; ++c) {
        const double builds = 100.0 + 5000.0 * u(rng), pixels = 2e5 + 2e6 * u(rng);
        CostRow b{"c" + std::to_string(c), {Pass::buildClusters}, {}, 0.0};
        b.features[CostFeature::threads] = builds;
        b.features[CostFeature::bytes] = 8000.0 * 1e5 / builds;  // the same particles in more or fewer clusters
        b.features[CostFeature::dispatches] = 2.0;
        b.features[CostFeature::build_launches] = builds;
        CostRow t{b.config, {Pass::traceShadowRays}, {}, 0.0};
        t.features[CostFeature::threads] = pixels;
        t.features[CostFeature::rays] = pixels * (0.2 + 0.3 * u(rng));
        t.features[CostFeature::blas_entries] = t.features[CostFeature::rays] * (2.0 + 6.0 * u(rng));
        t.features[CostFeature::blas_levels] = t.features[CostFeature::blas_entries] * (4.0 + 8.0 * u(rng));
        t.features[CostFeature::dispatches] = 1.0;
        for (CostRow* r : {&b, &t}) {
            r->measuredMs = truth.predictMs(r->pass.pass, r->features);
            rows.push_back(*r);
        }
    }
    const Holdout perPass = holdout(rows, CostModelForm::per_pass, 0.5, 1);
    REQUIRE(perPass.passes.size() == 3);  // two passes, then all passes
    CHECK(perPass.fitted.size() == 10);
    CHECK(perPass.predicted.size() == 10);
    for (const HoldoutError& e : perPass.passes) {
        INFO(e.label());
        CHECK(e.worst < 1e-6);
    }
    CHECK(perPass.frames.rows == 10);
    CHECK(perPass.frames.worst < 1e-6);
    const Holdout shared = holdout(rows, CostModelForm::shared, 0.5, 1);
    CHECK(shared.passes.back().worst > 0.3);
    // Its frames: each predicted configuration's passes summed, the error of the sums (not of the passes).
    std::map<std::string, std::pair<double, double>> sums;  // predicted, measured
    for (std::size_t i = 0; i < shared.rows.size(); ++i) {
        sums[shared.rows[i].config].first += shared.predictedMs[i];
        sums[shared.rows[i].config].second += shared.rows[i].measuredMs;
    }
    REQUIRE(sums.size() == 10);
    std::vector<double> frameErrors;
    for (const auto& [config, s] : sums) frameErrors.push_back(std::abs(s.first - s.second) / s.second);
    CHECK(shared.frames.rows == 10);
    CHECK(shared.frames.worst == Approx(*std::max_element(frameErrors.begin(), frameErrors.end())));
    CHECK(shared.frames.median == Approx(median(frameErrors)));
    CHECK(shared.iteratedSpatial.rows == 0);  // no spatial pass here
    // Spatial reuse run twice in half the configurations: its runs summed per configuration.
    std::vector<CostRow> spatialRows = rows;
    for (int c = 0; c < 20; ++c)
        for (std::uint32_t run = 1; run <= (c % 2 ? 2u : 1u); ++run) {
            CostRow r{"c" + std::to_string(c), {Pass::spatialResampling, run}, {}, 0.0};
            r.features[CostFeature::threads] = 1e5 * (1.0 + c);
            r.features[CostFeature::dispatches] = 1.0;
            r.measuredMs = 0.5 + 0.01 * c + 0.2 * run;
            spatialRows.push_back(r);
        }
    const Holdout spatial = holdout(spatialRows, CostModelForm::per_pass, 0.5, 1);
    std::map<std::string, std::pair<double, double>> runs;  // predicted, measured of the configurations run twice
    std::size_t twice = 0;
    for (const std::string& config : spatial.predicted) twice += std::stoi(config.substr(1)) % 2;
    for (std::size_t i = 0; i < spatial.rows.size(); ++i)
        if (spatial.rows[i].pass.pass == Pass::spatialResampling && std::stoi(spatial.rows[i].config.substr(1)) % 2) {
            runs[spatial.rows[i].config].first += spatial.predictedMs[i];
            runs[spatial.rows[i].config].second += spatial.rows[i].measuredMs;
        }
    REQUIRE(twice > 0);
    CHECK(spatial.iteratedSpatial.rows == twice);
    double worst = 0.0;
    for (const auto& [config, r] : runs) worst = std::max(worst, std::abs(r.first - r.second) / r.second);
    CHECK(spatial.iteratedSpatial.worst == Approx(worst));
    // The split is the seed's: the same seed, the same halves; another, others.
    CHECK(holdout(rows, CostModelForm::per_pass, 0.5, 1).fitted == perPass.fitted);
    CHECK(holdout(rows, CostModelForm::per_pass, 0.5, 2).fitted != perPass.fitted);

    // Fitted on all rows, the per-pass coefficients survive a save and load,
    // and spatialResampling[2]-style run labels use their pass's coefficients.
    const Calibration all = calibrate(rows, CostModelForm::per_pass);
    const auto file = std::filesystem::temp_directory_path() / "accretion_per_pass_coefficients.json";
    std::ofstream(file) << all.coefficients.toJson().dump();
    const CostCoefficients loaded = CostCoefficients::load(file.string());
    for (const CostRow& r : rows) {
        CHECK(loaded.predictMs(r.pass.pass, r.features) == Approx(r.measuredMs).epsilon(1e-6));
        CHECK(loaded.predictMs(parsePassRun(r.pass.label() + "[2]")->pass, r.features) == Approx(r.measuredMs).epsilon(1e-6));
    }
}

TEST_CASE("the selected form keeps the counters that made the timings and drops unrelated ones", "[gpu][cost]") {
    // traceShadowRays timed as 1.5 ns per ray + 0.03 ns per BLAS level +
    // 300 us per dispatch, with 3% noise; five other counters vary at random,
    // unrelated to the time. per_pass fits all eleven; selected must find the
    // three that made the time (leave-one-configuration-out), and recover them.
    CostFeatures truth{};
    truth[CostFeature::rays] = 1.5;
    truth[CostFeature::blas_levels] = 0.03;
    truth[CostFeature::dispatches] = 300000.0;
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::normal_distribution<double> noise(0.0, 0.03);
    std::vector<CostRow> rows;
    for (int c = 0; c < 40; ++c) {
        CostRow t{"c" + std::to_string(c), {Pass::traceShadowRays}, {}, 0.0};
        t.features[CostFeature::threads] = 2e5 + 2e6 * u(rng);  // unrelated here
        t.features[CostFeature::warp_steps] = 1e4 + 1e5 * u(rng);  // unrelated
        t.features[CostFeature::rays] = 1e5 + 1e6 * u(rng);
        t.features[CostFeature::any_hits] = 1e5 * u(rng);  // unrelated
        t.features[CostFeature::bytes] = 1e7 + 1e8 * u(rng);  // unrelated
        t.features[CostFeature::blas_levels] = t.features[CostFeature::rays] * (20.0 + 60.0 * u(rng));
        t.features[CostFeature::omm_lookups] = 1e5 * u(rng);  // unrelated
        t.features[CostFeature::dispatches] = 1.0;
        double ms = 0.0;
        for (std::size_t k = 0; k < truth.size(); ++k) ms += truth[k] * t.features[k] * 1e-6;
        t.measuredMs = ms * (1.0 + noise(rng));
        rows.push_back(t);
    }
    const Calibration c = calibrate(rows, CostModelForm::selected);
    const CostFeatures& ns = c.coefficients.perPass.at(Pass::traceShadowRays);
    for (const CostFeature k : {CostFeature::rays, CostFeature::blas_levels, CostFeature::dispatches}) {
        INFO(kCostFeatures[std::size_t(k)]);
        CHECK(ns[k] == Approx(truth[k]).epsilon(0.15));
    }
    for (const CostFeature k : {CostFeature::threads, CostFeature::warp_steps, CostFeature::any_hits, CostFeature::bytes, CostFeature::omm_lookups}) {
        INFO(kCostFeatures[std::size_t(k)]);
        CHECK(ns[k] == 0.0);
    }
}

TEST_CASE("calibrate finds the cache of the working-set term that made the timings", "[gpu][cost]") {
    // traceGBuffer timed as 0.5 ns per ray + 2 ns per cold read, where cold
    // reads are rays x log2(working set / 2 MiB) (0 below it), + 20 us per
    // dispatch; the working set (the BLAS bytes) spans 0.5 MiB to 500 MiB.
    const double cache = 2.0 * 1024 * 1024;
    CHECK(coldWork(100.0, 7.0, 0.5 * cache, cache) == 0.0);        // fits: no misses
    CHECK(coldWork(100.0, 7.0, 8.0 * cache, cache) == 300.0);      // 3 levels below the cache
    CHECK(coldWork(0.0, 7.0, 8.0 * cache, cache) == 21.0);         // no rays: its bytes
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<CostRow> rows;
    for (int c = 0; c < int(kCostFeatures.size()) + 2; ++c) {  // at least one row per coefficient
        CostRow r{"c" + std::to_string(c), {Pass::traceGBuffer}, {}, 0.0};
        r.features[CostFeature::threads] = r.features[CostFeature::rays] = 2e5 + 2e6 * u(rng);  // threads = rays
        r.features[CostFeature::dispatches] = 1.0;
        r.workingSetBytes = std::ldexp(0.5 * 1024 * 1024, c % 10);
        const double cold = coldWork(r.features[CostFeature::rays], 0.0, r.workingSetBytes, cache);
        r.measuredMs = (0.5 * r.features[CostFeature::rays] + 2.0 * cold + 20000.0) * 1e-6;
        rows.push_back(r);
    }
    for (CostModelForm form : {CostModelForm::per_pass, CostModelForm::selected}) {
        INFO(costModelFormName(form));
        const Calibration cal = calibrate(rows, form);
        CHECK(cal.coefficients.cacheBytes == cache);
        const CostFeatures& ns = cal.coefficients.perPass.at(Pass::traceGBuffer);
        CHECK(ns[CostFeature::cold_work] == Approx(2.0).epsilon(1e-6));
        CHECK(ns[CostFeature::rays] + ns[CostFeature::threads] == Approx(0.5).epsilon(1e-6));  // threads and rays are the same column here
        CHECK(cal.maxRelativeError < 1e-6);
    }
    // The cache travels with the coefficients.
    const auto file = std::filesystem::temp_directory_path() / "accretion_cache_coefficients.json";
    std::ofstream(file) << calibrate(rows, CostModelForm::per_pass).coefficients.toJson().dump();
    CHECK(CostCoefficients::load(file.string()).cacheBytes == cache);
}

TEST_CASE("a presampling pass without timings is priced with generateCandidates' coefficients", "[gpu][cost]") {
    CostCoefficients c;
    c.ns = {};
    c.ns[CostFeature::threads] = 1.0;  // shared: 1 ns per unit of the first feature
    CostFeatures candidates{};
    candidates[CostFeature::warp_steps] = 2.0;  // generateCandidates: 2 ns per unit of the second
    c.perPass[Pass::generateCandidates] = candidates;
    CostFeatures f{};
    f[CostFeature::threads] = 1e6;
    f[CostFeature::warp_steps] = 1e6;
    // 1e6 units x 2 ns = 2 ms by the proxy; the shared form would give 1 ms.
    CHECK(c.predictMs(Pass::presampleLightTiles, f) == Approx(2.0));
    CHECK(c.predictMs(Pass::presampleRegirGrid, f) == Approx(2.0));
    CHECK(c.predictMs(Pass::traceShadowRays, f) == Approx(1.0));  // no proxy: shared
    c.perPass[Pass::presampleRegirGrid] = CostFeatures{};  // its own coefficients, once fitted, win
    CHECK(c.predictMs(Pass::presampleRegirGrid, f) == Approx(0.0));
}

TEST_CASE("a build's elements are counted whole and clamped at the knots, refits and the TLAS apart", "[gpu][cost]") {
    BuildCounters b;
    b.addBlas(50, false);        // below both knots
    b.addBlas(2000, true);       // between them
    b.addBlas(2000000, false);   // above both
    b.addBlas(5000, true, true); // a refit: an element updated, not built
    b.addTlas(4, false);
    CHECK(b.builds == 4u);
    CHECK(b.refits == 1u);
    CHECK(b.blasBuilds == 3u);  // the TLAS is a launch, not a BLAS
    CHECK(b.blasRefits == 1u);
    CHECK(b.primitives == 50u + 2000u + 2000000u + 4u);
    CHECK(b.primitivesSmall == 50u + 1024u + 1024u + 4u);
    CHECK(b.primitivesMid == 50u + 2000u + 32768u + 4u);
    CHECK(b.elements == b.primitives + 5000u);
    CHECK(b.elementsSmall == b.primitivesSmall + 1024u);
    CHECK(b.elementsMid == b.primitivesMid + 5000u);
    CHECK(b.customBuilds == 1u);  // a refit of boxes costs what a refit of triangles does
    CHECK(b.sphereRefits == 0u);
    b.addBlas(700, true, true, true);  // built-in spheres refitted: dearer
    b.addBlas(700, true, false, true); // and built: a custom build
    CHECK(b.sphereRefits == 1u);
    CHECK(b.customBuilds == 2u);
    CHECK(b.tlasInstances == 4u);
    CHECK(b.tlasInstancesMid == 4u);  // the TLAS's instances again, apart from the BLAS's primitives
    BuildCounters refitTlas;
    refitTlas.addTlas(100000, true);
    CHECK(refitTlas.refits == 1u);
    CHECK(refitTlas.builds == 0u);
    CHECK(refitTlas.primitives == 0u);
    CHECK(refitTlas.elements == 100000u);
    CHECK(refitTlas.tlasInstancesMid == 0u);  // an update, not a build
    BuildCounters bigTlas;
    bigTlas.addTlas(1000000, false);
    CHECK(bigTlas.tlasInstancesMid == 32768u);
}

TEST_CASE("the build pass is fitted on the build counters, the other passes on the rest", "[gpu][cost]") {
    // Builds whose threads (one per cluster) track their launches: a fit
    // free to use threads could price the launches through them and then
    // charge a layout of one thread per particle (instances) for launches it
    // does not make. Fitted on build counters alone, it cannot.
    std::vector<CostRow> rows;
    for (int c = 0; c < int(kCostFeatures.size()) + 2; ++c) {  // at least one row per coefficient
        const double clusters = 10.0 + 100.0 * c;
        CostRow b{"c" + std::to_string(c), {Pass::buildClusters}, {}, 0.0};
        b.features[CostFeature::threads] = clusters;
        b.features[CostFeature::dispatches] = 1.0;
        b.features[CostFeature::build_launches] = clusters;
        b.measuredMs = 0.01 + 0.075 * clusters;
        rows.push_back(b);
    }
    const Calibration c = calibrate(rows, CostModelForm::per_pass);
    const CostFeatures& ns = c.coefficients.perPass.at(Pass::buildClusters);
    CHECK(ns[CostFeature::threads] == 0.0);
    CHECK(ns[CostFeature::build_launches] == Approx(75000.0).epsilon(1e-6));
    CostFeatures instances{};
    instances[CostFeature::threads] = 1e6;  // a thread per particle, one launch
    instances[CostFeature::dispatches] = 1.0;
    instances[CostFeature::build_launches] = 1.0;
    CHECK(c.coefficients.predictMs(Pass::buildClusters, instances) == Approx(0.085).epsilon(1e-6));
}

TEST_CASE("cost prices with the committed calibration, the uncalibrated guess only on request", "[gpu][cost]") {
    const CostCoefficients committed = CostCoefficients::forSetting("");
    REQUIRE(committed.calibrated);
    REQUIRE_FALSE(committed.gpu.empty());
    REQUIRE_FALSE(committed.measuredAt.empty());
    REQUIRE_THAT(committed.source, Catch::Matchers::Contains(kDefaultCoefficientsFile));
    // The per-pass coefficients of the passes the GPU timed, the BLAS builds' launch cost among them.
    for (const Pass pass : {Pass::buildClusters, Pass::traceGBuffer, Pass::traceShadowRays, Pass::generateCandidates})
        REQUIRE(committed.perPass.count(pass) == 1);
    // The file of the source tree, read as a file, is the same calibration.
    const CostCoefficients file = CostCoefficients::load(std::string(ACCRETION_SOURCE_DIR) + "/" + kDefaultCoefficientsFile);
    REQUIRE(file.perPass.at(Pass::buildClusters) == committed.perPass.at(Pass::buildClusters));
    const CostCoefficients guess = CostCoefficients::forSetting("uncalibrated");
    REQUIRE_FALSE(guess.calibrated);
    REQUIRE_THAT(guess.source, Catch::Matchers::Contains("uncalibrated"));
}

TEST_CASE("a pass timed once for all its runs joins its runs' counters summed, and timed run by run each its own", "[gpu][cost]") {
    const auto dir = accretion::test::scratchDir("cost_join_runs");
    const auto counters = [] {
        std::vector<CostRow> rows;
        for (std::uint32_t run : {1u, 2u}) {
            CostRow r{"a", {Pass::spatialResampling, run}, {}, 0.0};
            r.features[CostFeature::threads] = 100.0 * run;
            r.features[CostFeature::dispatches] = 1.0;
            r.workingSetBytes = 1000.0 * run;
            rows.push_back(r);
        }
        CostRow t{"a", {Pass::traceShadowRays}, {}, 0.0};
        t.features[CostFeature::rays] = 50.0;
        rows.push_back(t);
        return rows;
    };
    const auto write = [&](const std::string& name, const std::string& text) {
        std::ofstream(dir / name) << text;
        return (dir / name).string();
    };
    // As the twin times it: the spatial iterations' loop under the pass's name alone.
    std::vector<CostRow> total = counters();
    joinTimings(write("total.csv", "config,pass,ms\na,spatialResampling,3.0\na,traceShadowRays,1.0\n"), total);
    REQUIRE(total.size() == 2);
    const CostRow& s = total[0].pass.pass == Pass::spatialResampling ? total[0] : total[1];
    CHECK(s.runs == 2);
    CHECK(s.features[CostFeature::threads] == 300.0);
    CHECK(s.features[CostFeature::dispatches] == 2.0);
    CHECK(s.workingSetBytes == 2000.0);
    CHECK(s.measuredMs == 3.0);
    // Timed run by run: each run joins its own timing, nothing summed.
    std::vector<CostRow> perRun = counters();
    joinTimings(write("runs.csv", "config,pass,ms\na,spatialResampling,1.0\na,spatialResampling[2],2.0\na,traceShadowRays,1.0\n"),
                perRun);
    REQUIRE(perRun.size() == 3);
    for (const CostRow& r : perRun) {
        CHECK(r.runs == 1);
        if (r.pass.pass == Pass::spatialResampling) CHECK(r.measuredMs == double(r.pass.run));
    }
}

TEST_CASE("a pass timed in fewer than four configurations is priced as a scale of every pass's fit", "[gpu][cost]") {
    // Every pass costs 1.5 ns a ray and 200 us a dispatch, nothing a thread.
    // traceShadowRays is timed in 40 configurations of 1 to 10 M threads;
    // resampleWorldNeighbours in 2 of 1 M threads. A fit of those two rows
    // over every counter can put the dispatch's cost on the threads (they
    // are the same in both); a third configuration of 10 M threads tells.
    CostCoefficients truth;
    truth.ns[CostFeature::rays] = 1.5;
    truth.ns[CostFeature::dispatches] = 200000.0;
    auto row = [&](const std::string& config, Pass pass, double threads, double rays, double scale) {
        CostRow r{config, {pass}, {}, 0.0};
        r.features[CostFeature::threads] = threads;
        r.features[CostFeature::rays] = rays;
        r.features[CostFeature::dispatches] = 1.0;
        r.measuredMs = scale * truth.predictMs(r.features);
        return r;
    };
    std::vector<CostRow> rows;
    for (int c = 0; c < 40; ++c)
        rows.push_back(row("c" + std::to_string(c), Pass::traceShadowRays, 1e6 * (1 + (c * 7) % 10), 1e5 * (1 + c), 1.0));
    for (const double scale : {1.0, 1.25}) {
        INFO("scale " << scale);
        std::vector<CostRow> fitted = rows;
        fitted.push_back(row("c0", Pass::resampleWorldNeighbours, 1e6, 2e5, scale));
        fitted.push_back(row("c1", Pass::resampleWorldNeighbours, 1e6, 8e5, scale));
        const Calibration c = calibrate(fitted, CostModelForm::per_pass);
        const CostFeatures& world = c.coefficients.perPass.at(Pass::resampleWorldNeighbours);
        // The least relative error of s x the shared fit: s = sum(q) / sum(q^2), q = shared / measured.
        double num = 0.0, den = 0.0;
        for (const CostRow& r : fitted)
            if (r.pass.pass == Pass::resampleWorldNeighbours) {
                const double q = c.coefficients.predictMs(r.features) / r.measuredMs;
                num += q;
                den += q * q;
            }
        for (std::size_t k = 0; k < world.size(); ++k) CHECK(world[k] == Approx(num / den * c.coefficients.ns[k]).margin(1e-12));
        const CostRow unseen = row("c2", Pass::resampleWorldNeighbours, 1e7, 8e5, scale);
        const double predicted = c.coefficients.predictMs(Pass::resampleWorldNeighbours, unseen.features);
        if (scale == 1.0) {
            // The shared fit is exact here (every row follows the truth): the scale is 1, the unseen configuration priced exactly.
            CHECK(num / den == Approx(1.0).epsilon(1e-9));
            CHECK(predicted == Approx(unseen.measuredMs).epsilon(1e-6));
        } else {
            CHECK(num / den > 1.1);  // the pass's own level, not the shared fit's
            CHECK(predicted == Approx(unseen.measuredMs).epsilon(0.1));
        }
        // With four configurations the pass has a fit of its own over its counters.
        fitted.push_back(row("c2", Pass::resampleWorldNeighbours, 3e6, 4e5, scale));
        fitted.push_back(row("c3", Pass::resampleWorldNeighbours, 2e6, 1e5, scale));
        const CostCoefficients own = calibrate(fitted, CostModelForm::per_pass).coefficients;
        CHECK(own.predictMs(Pass::resampleWorldNeighbours, unseen.features) == Approx(unseen.measuredMs).epsilon(1e-6));
        CHECK(own.perPass.at(Pass::resampleWorldNeighbours)[CostFeature::rays] == Approx(scale * 1.5).epsilon(1e-6));
    }
}
