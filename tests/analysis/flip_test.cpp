// FLIP checked against what does not share its code: the published CIE
// L*a*b* coordinates of the sRGB primaries (closed-form FLIP of uniform
// images), a brute-force 2-D implementation of the paper's filters
// (non-separable, on the pixel grid), and Narkowicz's ACES formula solved
// by bisection for HDR-FLIP's exposure range.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include "accretion/analysis/flip.h"

using namespace accretion;

namespace {

constexpr double kPi = 3.14159265358979323846;

std::vector<Vec3> uniform(std::size_t n, Vec3 c) { return std::vector<Vec3>(n, c); }

/// Hunt-adjusted HyAB distance to the power 0.7 from published L*a*b* values.
double huntHyab(double L1, double a1, double b1, double L2, double a2, double b2) {
    const double d = std::fabs(L1 - L2) + std::hypot(0.01 * L1 * a1 - 0.01 * L2 * a2, 0.01 * L1 * b1 - 0.01 * L2 * b2);
    return std::pow(d, 0.7);
}

// CIE L*a*b* (D65) of sRGB green and blue, as colour references tabulate them.
constexpr double kGreen[3] = {87.7347, -86.1827, 83.1793}, kBlue[3] = {32.2970, 79.1875, -107.8602};

double compress(double e, double cmax) {
    return e < 0.4 * cmax ? 0.95 / (0.4 * cmax) * e : 0.95 + (e - 0.4 * cmax) / (0.6 * cmax) * 0.05;
}

/// FLIP from the paper's definitions with full 2-D kernels (no separation),
/// replicated borders: an independent implementation for small images.
std::vector<double> bruteFlip(const std::vector<Vec3>& ref, const std::vector<Vec3>& test, int w, int h, double ppd) {
    auto lin = [](double v) { return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4); };
    const double M[3][3] = {{0.4123908, 0.3575843, 0.1804808}, {0.2126390, 0.7151687, 0.0721923}, {0.0193308, 0.1191948, 0.9505322}};
    double Mi[3][3];
    {  // inverse by cofactors
        const double det = M[0][0] * (M[1][1] * M[2][2] - M[1][2] * M[2][1]) - M[0][1] * (M[1][0] * M[2][2] - M[1][2] * M[2][0]) +
                           M[0][2] * (M[1][0] * M[2][1] - M[1][1] * M[2][0]);
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) {
                const int r0 = (j + 1) % 3, r1 = (j + 2) % 3, c0 = (i + 1) % 3, c1 = (i + 2) % 3;
                Mi[i][j] = (M[r0][c0] * M[r1][c1] - M[r0][c1] * M[r1][c0]) / det;
            }
    }
    const double Wn[3] = {M[0][0] + M[0][1] + M[0][2], 1.0, M[2][0] + M[2][1] + M[2][2]};
    auto mul = [](const double A[3][3], const double v[3], double out[3]) {
        for (int i = 0; i < 3; ++i) out[i] = A[i][0] * v[0] + A[i][1] * v[1] + A[i][2] * v[2];
    };
    auto lab = [&](const double xyz[3], double out[3]) {
        auto f = [](double t) { const double d = 6.0 / 29.0; return t > d * d * d ? std::cbrt(t) : t / (3 * d * d) + 4.0 / 29.0; };
        const double fx = f(xyz[0] / Wn[0]), fy = f(xyz[1] / Wn[1]), fz = f(xyz[2] / Wn[2]);
        const double L = 116 * fy - 16;
        out[0] = L;
        out[1] = 0.01 * L * 500 * (fx - fy);
        out[2] = 0.01 * L * 200 * (fy - fz);
    };
    const int n = w * h;
    // Opponent channels and the achromatic channel of each image.
    auto opponent = [&](const std::vector<Vec3>& img, std::vector<std::array<double, 3>>& o, std::vector<double>& y) {
        o.resize(n);
        y.resize(n);
        for (int i = 0; i < n; ++i) {
            const double rgb[3] = {lin(img[i].x), lin(img[i].y), lin(img[i].z)};
            double xyz[3];
            mul(M, rgb, xyz);
            o[i] = {116 * xyz[1] / Wn[1] - 16, 500 * (xyz[0] / Wn[0] - xyz[1] / Wn[1]), 200 * (xyz[1] / Wn[1] - xyz[2] / Wn[2])};
            y[i] = (o[i][0] + 16) / 116;
        }
    };
    std::vector<std::array<double, 3>> oR, oT;
    std::vector<double> yR, yT;
    opponent(ref, oR, yR);
    opponent(test, oT, yT);
    const double csf[3][4] = {{1, 0.0047, 0, 1e-5}, {1, 0.0053, 0, 1e-5}, {34.1, 0.04, 13.5, 0.025}};
    const int r = int(std::ceil(3 * std::sqrt(0.04 / (2 * kPi * kPi)) * ppd));
    auto at = [&](int x, int y) { return std::clamp(y, 0, h - 1) * w + std::clamp(x, 0, w - 1); };
    auto filtered = [&](const std::vector<std::array<double, 3>>& o, std::vector<std::array<double, 3>>& lab3) {
        lab3.resize(n);
        for (int py = 0; py < h; ++py)
            for (int px = 0; px < w; ++px) {
                double c[3];
                for (int ch = 0; ch < 3; ++ch) {
                    double s = 0, sw = 0;
                    for (int dy = -r; dy <= r; ++dy)
                        for (int dx = -r; dx <= r; ++dx) {
                            const double z = (dx * dx + dy * dy) / (ppd * ppd);
                            const double k = csf[ch][0] * std::sqrt(kPi / csf[ch][1]) * std::exp(-kPi * kPi * z / csf[ch][1]) +
                                             csf[ch][2] * std::sqrt(kPi / csf[ch][3]) * std::exp(-kPi * kPi * z / csf[ch][3]);
                            s += k * o[at(px + dx, py + dy)][ch];
                            sw += k;
                        }
                    c[ch] = s / sw;
                }
                const double Y = (c[0] + 16) / 116;
                const double xyz[3] = {(Y + c[1] / 500) * Wn[0], Y, (Y - c[2] / 200) * Wn[2]};
                double rgb[3], back[3];
                mul(Mi, xyz, rgb);
                for (double& v : rgb) v = std::clamp(v, 0.0, 1.0);
                mul(M, rgb, back);
                double l[3];
                lab(back, l);
                lab3[at(px, py)] = {l[0], l[1], l[2]};
            }
    };
    std::vector<std::array<double, 3>> lR, lT;
    filtered(oR, lR);
    filtered(oT, lT);
    // 2-D feature kernels, normalised over the whole 2-D kernel.
    const double sd = 0.5 * 0.082 * ppd;
    const int fr = int(std::ceil(3 * sd));
    const int size = 2 * fr + 1;
    std::vector<double> E(size * size), P(size * size);
    double ep = 0, en = 0, pp = 0, pn = 0;
    for (int y = -fr; y <= fr; ++y)
        for (int x = -fr; x <= fr; ++x) {
            const double g = std::exp(-(x * x + y * y) / (2 * sd * sd));
            const double e = -x * g, p = (x * x / (sd * sd) - 1) * g;
            E[(y + fr) * size + x + fr] = e;
            P[(y + fr) * size + x + fr] = p;
            (e > 0 ? ep : en) += e;
            (p > 0 ? pp : pn) += p;
        }
    for (double& e : E) e = e > 0 ? e / ep : e < 0 ? e / -en : 0;
    for (double& p : P) p = p > 0 ? p / pp : p < 0 ? p / -pn : 0;
    auto feature = [&](const std::vector<double>& y, const std::vector<double>& K, int px, int py) {
        double gx = 0, gy = 0;
        for (int dy = -fr; dy <= fr; ++dy)
            for (int dx = -fr; dx <= fr; ++dx) {
                gx += K[(dy + fr) * size + dx + fr] * y[at(px + dx, py + dy)];
                gy += K[(dx + fr) * size + dy + fr] * y[at(px + dx, py + dy)];  // the transposed kernel
            }
        return std::hypot(gx, gy);
    };
    const double cmax = huntHyab(kGreen[0], kGreen[1], kGreen[2], kBlue[0], kBlue[1], kBlue[2]);
    std::vector<double> out(n);
    for (int py = 0; py < h; ++py)
        for (int px = 0; px < w; ++px) {
            const int i = at(px, py);
            const double d = std::fabs(lR[i][0] - lT[i][0]) + std::hypot(lR[i][1] - lT[i][1], lR[i][2] - lT[i][2]);
            const double c = compress(std::pow(d, 0.7), cmax);
            const double f = std::pow(std::max(std::fabs(feature(yR, E, px, py) - feature(yT, E, px, py)),
                                               std::fabs(feature(yR, P, px, py) - feature(yT, P, px, py))) / std::sqrt(2.0), 0.5);
            out[i] = std::pow(c, 1 - f);
        }
    return out;
}

}  // namespace

TEST_CASE("FLIP of uniform images: the colour term in closed form", "[flip]") {
    const std::size_t n = 32 * 24;
    // Same image: no difference anywhere.
    for (float v : ldrFlip(uniform(n, Vec3(0.3f, 0.5f, 0.1f)), uniform(n, Vec3(0.3f, 0.5f, 0.1f)), 32, 24)) REQUIRE(v == 0.0f);
    // Green against blue is the largest colour difference: FLIP 1 (the
    // published L*a*b* of the primaries agree with ours to their 4 decimals).
    for (float v : ldrFlip(uniform(n, Vec3(0, 1, 0)), uniform(n, Vec3(0, 0, 1)), 32, 24)) REQUIRE(v == Approx(1.0).margin(1e-5));
    // Black against white: L* 0 against 100, no chroma, no features.
    const double cmax = huntHyab(kGreen[0], kGreen[1], kGreen[2], kBlue[0], kBlue[1], kBlue[2]);
    const double expected = compress(std::pow(100.0, 0.7), cmax);
    CHECK(expected == Approx(0.9674).margin(2e-4));  // 0.95 + (25.12 - 16.51) / 24.76 * 0.05, by hand
    for (float v : ldrFlip(uniform(n, Vec3(0.0f)), uniform(n, Vec3(1.0f)), 32, 24)) REQUIRE(v == Approx(expected).epsilon(1e-4));
    // Mid grey against a lighter grey: below the knee, linear in HyAB^0.7.
    auto Lstar = [](double srgb) {
        const double Y = srgb <= 0.04045 ? srgb / 12.92 : std::pow((srgb + 0.055) / 1.055, 2.4);
        return 116.0 * std::cbrt(Y) - 16.0;
    };
    const double grey = compress(std::pow(std::fabs(Lstar(0.5) - Lstar(0.6)), 0.7), cmax);
    for (float v : ldrFlip(uniform(n, Vec3(0.5f)), uniform(n, Vec3(0.6f)), 32, 24)) REQUIRE(v == Approx(grey).epsilon(1e-4));
}

TEST_CASE("FLIP equals a brute-force 2-D implementation of the paper's filters", "[flip]") {
    const int w = 23, h = 17;
    std::mt19937 gen(7);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    std::vector<Vec3> ref(w * h), test(w * h);
    for (int i = 0; i < w * h; ++i) {
        ref[i] = Vec3(u(gen), u(gen), u(gen));
        // The test: a blurred-ish copy with noise, and an edge moved.
        test[i] = glm::clamp(ref[i] + Vec3(0.2f * (u(gen) - 0.5f)), 0.0f, 1.0f);
        if (i % w > 15) test[i] = Vec3(0.9f, 0.2f, 0.1f);
    }
    for (double ppd : {67.02, 20.0}) {
        const std::vector<float> fast = ldrFlip(ref, test, w, h, {ppd});
        const std::vector<double> slow = bruteFlip(ref, test, w, h, ppd);
        double worst = 0.0, mean = 0.0;
        for (int i = 0; i < w * h; ++i) {
            worst = std::max(worst, std::fabs(double(fast[i]) - slow[i]));
            mean += slow[i] / (w * h);
        }
        INFO("ppd " << ppd << ": mean FLIP " << mean);
        CHECK(mean > 0.05);
        CHECK(worst < 1e-4);
    }
}

TEST_CASE("HDR-FLIP: ACES tone map and exposure range from the reference", "[flip]") {
    // Narkowicz's fit: x' = 0.6 x, (x'(2.51 x' + 0.03)) / (x'(2.43 x' + 0.59) + 0.14).
    auto aces = [](double x) { x *= 0.6; return std::clamp(x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0); };
    for (double x : {0.0, 0.01, 0.18, 1.0, 4.0, 100.0}) CHECK(acesToneMap(float(x)) == Approx(aces(x)).epsilon(1e-6));
    // The x that maps to 0.85, by bisection.
    double lo = 0.0, hi = 100.0;
    for (int k = 0; k < 200; ++k) (aces(0.5 * (lo + hi)) < 0.85 ? lo : hi) = 0.5 * (lo + hi);
    const double x85 = 0.5 * (lo + hi);
    // Luminances 0 (a black sky, 70%), 1 .. 29, and one bright pixel of 500:
    // the median of the lit pixels (a mostly black frame) is used.
    std::vector<Vec3> img;
    for (int k = 0; k < 70; ++k) img.push_back(Vec3(0.0f));
    for (int k = 1; k <= 30; ++k) img.push_back(Vec3(float(k)));
    img.back() = Vec3(500.0f);
    const auto [start, stop] = flipExposureRange(img);
    CHECK(start == Approx(std::log2(x85 / 500.0)).epsilon(1e-9));
    CHECK(stop == Approx(std::log2(x85 / 15.5)).epsilon(1e-9));  // median of 1 .. 29, 500
    // A frame mostly lit takes the plain median: 0 x 10, 1 .. 30 -> 10.5.
    std::vector<Vec3> lit(img.begin() + 60, img.end());
    CHECK(flipExposureRange(lit).second == Approx(std::log2(x85 / 10.5)).epsilon(1e-9));
    // An HDR image against itself, and against a copy 4x brighter in one half.
    std::vector<Vec3> a(64 * 48), b;
    for (std::size_t i = 0; i < a.size(); ++i) a[i] = Vec3(0.05f + 0.001f * float(i % 64), 0.2f, 2.0f + float(i / 64) * 0.1f);
    b = a;
    const HdrFlip same = hdrFlip(a, b, 64, 48);
    for (float v : same.error) REQUIRE(v == 0.0f);
    for (std::size_t i = 0; i < b.size(); ++i)
        if (i % 64 >= 32) b[i] *= 4.0f;
    const HdrFlip diff = hdrFlip(a, b, 64, 48);
    CHECK(diff.exposures == std::max(2, int(std::ceil(diff.stopExposure - diff.startExposure))));
    CHECK(diff.error[10 * 64 + 5] < 0.05f);   // far from the changed half
    CHECK(diff.error[10 * 64 + 50] > 0.3f);   // 2 stops brighter
}
