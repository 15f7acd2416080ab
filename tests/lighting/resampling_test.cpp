// The resampling core on its own: MIS weights of the three bias
// corrections, the basic normalisation and the neighbour test, as plain
// values (lighting/resampling.h), against closed forms and a hand-computed case.
#include <random>

#include <catch2/catch.hpp>

#include "accretion/lighting/resampling.h"

using namespace accretion;
using namespace accretion::resampling;

namespace {

double sum(const std::vector<double>& v) {
    double s = 0.0;
    for (double x : v) s += x;
    return s;
}

}  // namespace

TEST_CASE("MIS weights of every sample sum to 1 over the domains that can produce it", "[resampling]") {
    std::mt19937 gen(5);
    std::uniform_real_distribution<double> uM(1.0, 40.0), up(0.0, 3.0);
    for (int trial = 0; trial < 200; ++trial) {
        const std::size_t n = 1 + trial % 9;
        std::vector<double> M(n), p(n);
        for (std::size_t i = 0; i < n; ++i) {
            M[i] = std::floor(uM(gen));
            p[i] = trial % 3 == 0 && i % 2 ? 0.0 : up(gen) + 1e-3;  // some domains cannot produce y
        }
        p[0] = up(gen) + 1e-3;  // the canonical domain produced y
        INFO("trial " << trial << ", " << n << " domains");
        CHECK(sum(misWeightsPairwise(M, p)) == Approx(1.0).epsilon(1e-12));
        CHECK(sum(misWeightsBasic(M, p)) == Approx(1.0).epsilon(1e-12));
        // none (1/M): sums to the share of M held by domains that can produce y.
        const std::vector<double> none = misWeightsNone(M);
        double share = 0.0, total = sum(M);
        for (std::size_t i = 0; i < n; ++i) share += p[i] > 0.0 ? M[i] / total : 0.0;
        double covered = 0.0;
        for (std::size_t i = 0; i < n; ++i) covered += p[i] > 0.0 ? none[i] : 0.0;
        CHECK(covered == Approx(share).epsilon(1e-12));
    }
}

TEST_CASE("equal targets give every domain M_i / M_total", "[resampling]") {
    const std::vector<double> M{20, 4, 1, 7};
    const std::vector<double> p(4, 0.37);
    for (const auto& m : {misWeightsNone(M), misWeightsBasic(M, p), misWeightsPairwise(M, p)})
        for (std::size_t i = 0; i < M.size(); ++i) CHECK(m[i] == Approx(M[i] / 32.0).epsilon(1e-14));
}

TEST_CASE("basic counts only the domains whose target of y is non-zero", "[resampling]") {
    const std::vector<double> M{10, 5, 3, 2};
    const std::vector<double> p{0.5, 0.0, 1.0, 0.0};
    const std::vector<double> m = misWeightsBasic(M, p);
    CHECK(m[0] == Approx(10.0 / 13.0));
    CHECK(m[1] == 0.0);
    CHECK(m[2] == Approx(3.0 / 13.0));
    CHECK(m[3] == 0.0);
    // The normalisation combineReservoirs uses: the chosen domain always counts.
    const std::vector<std::uint32_t> Mi{10, 5, 3, 2};
    CHECK(basicNormalization(Mi, std::vector<std::uint8_t>{0, 0, 1, 0}, 0) == 13.0);
    CHECK(basicNormalization(Mi, std::vector<std::uint8_t>{0, 0, 0, 0}, 1) == 5.0);
    CHECK(basicNormalization(Mi, std::vector<std::uint8_t>{1, 1, 1, 1}, 3) == 20.0);
}

TEST_CASE("pairwise MIS against a hand-computed case", "[resampling]") {
    // Canonical M_c = 4, p_c(y) = 2; neighbours (M, p(y)) = (2, 1) and (6, 3);
    // k = 2, M_c / k = 2, M_total = 12.
    // neighbour 1: a = 2, b = 2 * 2 = 4: (2 + 2) / 12 * 2 / 6 = 1/9
    // neighbour 2: a = 18, b = 4:       (6 + 2) / 12 * 18 / 22 = 6/11
    // canonical: 4/12 * 4/6 + 8/12 * 4/22 = 2/9 + 4/33
    const std::vector<double> M{4, 2, 6}, p{2, 1, 3};
    const std::vector<double> m = misWeightsPairwise(M, p);
    CHECK(m[1] == Approx(1.0 / 9.0).epsilon(1e-14));
    CHECK(m[2] == Approx(6.0 / 11.0).epsilon(1e-14));
    CHECK(m[0] == Approx(2.0 / 9.0 + 4.0 / 33.0).epsilon(1e-14));
    CHECK(pairwiseCanonicalTerm(2, 1, 4, 2, 2, 12) == Approx(4.0 / 12.0 * 4.0 / 6.0));
    CHECK(pairwiseNeighbourWeight(6, 3, 4, 2, 2, 12) == Approx(6.0 / 11.0));
    // A neighbour that cannot produce y and a canonical that cannot: weight 0, not NaN.
    CHECK(pairwiseNeighbourWeight(6, 0, 4, 2, 0, 12) == 0.0);
}

TEST_CASE("neighbour test: normal within the threshold, depth within a fraction of the receiver's", "[resampling]") {
    const Vec3 n(0, 0, 1);
    CHECK(similarSurface(n, 10.0f, n, 10.9f, 0.9f, 0.1f));
    CHECK_FALSE(similarSurface(n, 10.0f, n, 11.1f, 0.9f, 0.1f));
    CHECK(similarSurface(n, 10.0f, n, 9.1f, 0.9f, 0.1f));
    CHECK_FALSE(similarSurface(n, 10.0f, glm::normalize(Vec3(1, 0, 1)), 10.0f, 0.9f, 0.1f));  // cos = 0.707
    CHECK(similarSurface(n, 10.0f, glm::normalize(Vec3(0.3f, 0, 1)), 10.0f, 0.9f, 0.1f));  // cos = 0.958
}
