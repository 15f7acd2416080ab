// FLIP and HDR-FLIP, written from the papers (see analysis/flip.h): the
// colour pipeline filters the opponent channels with the contrast
// sensitivity functions, the feature pipeline detects edges and points in
// the achromatic channel. Every 2-D kernel is separable (or a sum of two
// separable Gaussians), so the filters run as two 1-D passes, borders
// replicated.
#include "accretion/analysis/flip.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace accretion {
namespace {

constexpr double kPi = 3.14159265358979323846;

/// sRGB primaries, D65 white: linear RGB -> XYZ (the exact ratios of the
/// sRGB definition), and its inverse.
const glm::dmat3 kRgbToXyz = glm::transpose(glm::dmat3(10135552.0 / 24577794.0, 8788810.0 / 24577794.0, 4435075.0 / 24577794.0,
                                                       2613072.0 / 12288897.0, 8788810.0 / 12288897.0, 887015.0 / 12288897.0,
                                                       1425312.0 / 73733382.0, 8788810.0 / 73733382.0, 70074185.0 / 73733382.0));
const glm::dmat3 kXyzToRgb = glm::inverse(kRgbToXyz);
/// The reference white: XYZ of RGB (1, 1, 1).
const glm::dvec3 kWhite = kRgbToXyz * glm::dvec3(1.0);

/// XYZ -> YyCxCz (the linear opponent space of the CSF filtering) and back.
glm::dvec3 xyzToYcxcz(const glm::dvec3& xyz) {
    const glm::dvec3 n = xyz / kWhite;
    return {116.0 * n.y - 16.0, 500.0 * (n.x - n.y), 200.0 * (n.y - n.z)};
}
glm::dvec3 ycxczToXyz(const glm::dvec3& c) {
    const double y = (c.x + 16.0) / 116.0;
    return glm::dvec3(y + c.y / 500.0, y, y - c.z / 200.0) * kWhite;
}
/// CIE L*a*b* of XYZ, then the Hunt adjustment (chroma scaled by L*/100).
glm::dvec3 huntLab(const glm::dvec3& xyz) {
    constexpr double d = 6.0 / 29.0;
    auto f = [](double t) { return t > d * d * d ? std::cbrt(t) : t / (3.0 * d * d) + 4.0 / 29.0; };
    const glm::dvec3 n = xyz / kWhite;
    const double L = 116.0 * f(n.y) - 16.0, a = 500.0 * (f(n.x) - f(n.y)), b = 200.0 * (f(n.y) - f(n.z));
    return {L, 0.01 * L * a, 0.01 * L * b};
}
double hyab(const glm::dvec3& p, const glm::dvec3& q) {
    return std::fabs(p.x - q.x) + std::hypot(p.y - q.y, p.z - q.z);
}

constexpr double kQc = 0.7, kQf = 0.5, kPc = 0.4, kPt = 0.95;

/// The largest colour difference: Hunt-adjusted green against blue, to the power q_c.
double colourMax() { return std::pow(hyab(huntLab(kRgbToXyz * glm::dvec3(0, 1, 0)), huntLab(kRgbToXyz * glm::dvec3(0, 0, 1))), kQc); }

/// An image plane of floats.
struct Plane {
    std::uint32_t w = 0, h = 0;
    std::vector<float> v;
    float at(int x, int y) const { return v[std::size_t(y) * w + x]; }
};

/// Correlate rows with kx, then columns with ky, borders replicated.
Plane filterSeparable(const Plane& in, const std::vector<double>& kx, const std::vector<double>& ky) {
    const int rx = int(kx.size() / 2), ry = int(ky.size() / 2);
    const int W = int(in.w), H = int(in.h);
    Plane tmp{in.w, in.h, std::vector<float>(in.v.size())}, out = tmp;
    tbb::parallel_for(tbb::blocked_range<int>(0, H, 16), [&](const auto& r) {
        for (int y = r.begin(); y != r.end(); ++y)
            for (int x = 0; x < W; ++x) {
                double s = 0.0;
                for (int k = -rx; k <= rx; ++k) s += kx[k + rx] * in.at(std::clamp(x + k, 0, W - 1), y);
                tmp.v[std::size_t(y) * W + x] = float(s);
            }
    });
    tbb::parallel_for(tbb::blocked_range<int>(0, H, 16), [&](const auto& r) {
        for (int y = r.begin(); y != r.end(); ++y)
            for (int x = 0; x < W; ++x) {
                double s = 0.0;
                for (int k = -ry; k <= ry; ++k) s += ky[k + ry] * tmp.at(x, std::clamp(y + k, 0, H - 1));
                out.v[std::size_t(y) * W + x] = float(s);
            }
    });
    return out;
}

/// One contrast sensitivity function: a1 sqrt(pi/b1) exp(-pi^2 r^2 / b1)
/// (+ the same with a2, b2), r in degrees, sampled on the pixel grid within
/// the radius of the widest of the three CSFs and normalised to sum 1.
struct Csf {
    double a1, b1, a2, b2;
};
constexpr Csf kCsfA{1.0, 0.0047, 0.0, 1e-5}, kCsfRg{1.0, 0.0053, 0.0, 1e-5}, kCsfBy{34.1, 0.04, 13.5, 0.025};

Plane filterCsf(const Plane& in, const Csf& c, double ppd) {
    const int r = int(std::ceil(3.0 * std::sqrt(0.04 / (2.0 * kPi * kPi)) * ppd));
    auto gaussian = [&](double b) {
        std::vector<double> g(2 * r + 1);
        for (int k = -r; k <= r; ++k) g[k + r] = std::exp(-kPi * kPi * (k / ppd) * (k / ppd) / b);
        return g;
    };
    auto sum = [](const std::vector<double>& g) { double s = 0.0; for (double x : g) s += x; return s; };
    // Each term is a product of 1-D Gaussians; the 2-D sum of a term is the square of its 1-D sum.
    const std::vector<double> g1 = gaussian(c.b1), g2 = gaussian(c.b2);
    const double w1 = c.a1 * std::sqrt(kPi / c.b1), w2 = c.a2 * std::sqrt(kPi / c.b2);
    const double total = w1 * sum(g1) * sum(g1) + w2 * sum(g2) * sum(g2);
    Plane out = filterSeparable(in, g1, g1);
    for (float& v : out.v) v = float(double(v) * w1 / total);
    if (w2 > 0.0) {
        const Plane second = filterSeparable(in, g2, g2);
        for (std::size_t i = 0; i < out.v.size(); ++i) out.v[i] += float(double(second.v[i]) * w2 / total);
    }
    return out;
}

/// The feature detectors: first (edges) and second (points) derivatives of
/// a Gaussian of standard deviation 0.5 w ppd (w = 0.082 degrees), their
/// positive weights scaled to sum 1 and negative to sum -1; across, the
/// Gaussian itself (normalised).
struct FeatureKernels {
    std::vector<double> edge, point, smooth;
};
FeatureKernels featureKernels(double ppd) {
    const double sd = 0.5 * 0.082 * ppd;
    const int r = int(std::ceil(3.0 * sd));
    FeatureKernels k;
    double gs = 0.0;
    for (int x = -r; x <= r; ++x) {
        const double g = std::exp(-double(x) * x / (2.0 * sd * sd));
        k.smooth.push_back(g);
        k.edge.push_back(-x * g);
        k.point.push_back((double(x) * x / (sd * sd) - 1.0) * g);
        gs += g;
    }
    for (double& g : k.smooth) g /= gs;
    for (auto* f : {&k.edge, &k.point}) {
        double pos = 0.0, neg = 0.0;
        for (double v : *f) (v > 0 ? pos : neg) += v;
        for (double& v : *f) v = v > 0 ? v / pos : v < 0 ? v / -neg : 0.0;
    }
    return k;
}

/// What FLIP compares of one image: the Hunt-adjusted L*a*b* after CSF
/// filtering, and the edge and point magnitudes of the achromatic channel.
struct Prepared {
    std::vector<glm::dvec3> lab;
    std::vector<float> edges, points;
};

Prepared prepare(const std::vector<Vec3>& srgb, std::uint32_t w, std::uint32_t h, double ppd) {
    const std::size_t n = std::size_t(w) * h;
    std::array<Plane, 3> opp;
    for (auto& p : opp) p = Plane{w, h, std::vector<float>(n)};
    Plane y{w, h, std::vector<float>(n)};  // achromatic, normalised to [0, 1]
    for (std::size_t i = 0; i < n; ++i) {
        const glm::dvec3 lin(srgbToLinear(srgb[i].x), srgbToLinear(srgb[i].y), srgbToLinear(srgb[i].z));
        const glm::dvec3 c = xyzToYcxcz(kRgbToXyz * lin);
        for (int k = 0; k < 3; ++k) opp[k].v[i] = float(c[k]);
        y.v[i] = float((c.x + 16.0) / 116.0);
    }
    const Plane fa = filterCsf(opp[0], kCsfA, ppd), frg = filterCsf(opp[1], kCsfRg, ppd), fby = filterCsf(opp[2], kCsfBy, ppd);
    Prepared p;
    p.lab.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        const glm::dvec3 rgb = glm::clamp(kXyzToRgb * ycxczToXyz({fa.v[i], frg.v[i], fby.v[i]}), 0.0, 1.0);
        p.lab[i] = huntLab(kRgbToXyz * rgb);
    }
    const FeatureKernels k = featureKernels(ppd);
    const Plane ex = filterSeparable(y, k.edge, k.smooth), ey = filterSeparable(y, k.smooth, k.edge);
    const Plane px = filterSeparable(y, k.point, k.smooth), py = filterSeparable(y, k.smooth, k.point);
    p.edges.resize(n);
    p.points.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        p.edges[i] = std::hypot(ex.v[i], ey.v[i]);
        p.points[i] = std::hypot(px.v[i], py.v[i]);
    }
    return p;
}

}  // namespace

std::vector<float> ldrFlip(const std::vector<Vec3>& reference, const std::vector<Vec3>& test, std::uint32_t w, std::uint32_t h,
                           const FlipOptions& options) {
    const Prepared r = prepare(reference, w, h, options.ppd), t = prepare(test, w, h, options.ppd);
    const double cmax = colourMax();
    std::vector<float> out(reference.size());
    for (std::size_t i = 0; i < out.size(); ++i) {
        const double e = std::pow(hyab(r.lab[i], t.lab[i]), kQc);
        const double colour = e < kPc * cmax ? kPt / (kPc * cmax) * e : kPt + (e - kPc * cmax) / (cmax - kPc * cmax) * (1.0 - kPt);
        const double feature = std::pow(std::max(std::fabs(double(r.edges[i]) - t.edges[i]),
                                                 std::fabs(double(r.points[i]) - t.points[i])) / std::sqrt(2.0), kQf);
        out[i] = float(std::pow(colour, 1.0 - feature));
    }
    return out;
}

namespace {
// ACES fit with its 0.6 pre-exposure folded into the coefficients:
// (k0 x^2 + k1 x) / (k3 x^2 + k4 x + k5).
constexpr double kA0 = 0.6 * 0.6 * 2.51, kA1 = 0.6 * 0.03, kA3 = 0.6 * 0.6 * 2.43, kA4 = 0.6 * 0.59, kA5 = 0.14;

/// The x that the ACES fit maps to t.
double acesInverse(double t) {
    const double c0 = (kA1 - kA4 * t) / (kA0 - kA3 * t), c1 = (0.0 - kA5 * t) / (kA0 - kA3 * t);
    return -0.5 * c0 + std::sqrt(0.25 * c0 * c0 - c1);
}
}  // namespace

std::pair<double, double> flipExposureRange(const std::vector<Vec3>& reference) {
    std::vector<double> Y;
    Y.reserve(reference.size());
    double hi = 0.0;
    for (const Vec3& c : reference) {
        const double y = 0.2126 * std::max(c.x, 0.0f) + 0.7152 * std::max(c.y, 0.0f) + 0.0722 * std::max(c.z, 0.0f);
        Y.push_back(y);
        hi = std::max(hi, y);
    }
    if (hi <= 0.0) return {0.0, 0.0};
    // The median luminance (linear interpolation between order statistics);
    // an image mostly black (a particle disk on an empty sky) takes the
    // median of its non-black pixels, where the 50th percentile is 0.
    auto median = [](std::vector<double> v) {
        std::sort(v.begin(), v.end());
        const double pos = 0.5 * double(v.size() - 1);
        const std::size_t i = std::size_t(pos);
        return i + 1 < v.size() ? v[i] + (pos - double(i)) * (v[i + 1] - v[i]) : v[i];
    };
    double lo = median(Y);
    if (lo <= 0.0) {
        std::vector<double> lit;
        for (double y : Y)
            if (y > 0.0) lit.push_back(y);
        lo = median(std::move(lit));
    }
    const double t = 0.85;
    return {std::log2(acesInverse(t) / hi), std::log2(acesInverse(t) / lo)};
}

HdrFlip hdrFlip(const std::vector<Vec3>& reference, const std::vector<Vec3>& test, std::uint32_t w, std::uint32_t h,
                const FlipOptions& options) {
    HdrFlip out;
    std::tie(out.startExposure, out.stopExposure) = flipExposureRange(reference);
    out.exposures = std::max(2, int(std::ceil(out.stopExposure - out.startExposure)));
    const double step = (out.stopExposure - out.startExposure) / double(out.exposures - 1);
    out.error.assign(reference.size(), 0.0f);
    std::vector<Vec3> r(reference.size()), t(test.size());
    for (int e = 0; e < out.exposures; ++e) {
        const float scale = float(std::exp2(out.startExposure + e * step));
        for (std::size_t i = 0; i < r.size(); ++i)
            for (int c = 0; c < 3; ++c) {
                r[i][c] = linearToSrgb(acesToneMap(scale * reference[i][c]));
                t[i][c] = linearToSrgb(acesToneMap(scale * test[i][c]));
            }
        const std::vector<float> ldr = ldrFlip(r, t, w, h, options);
        for (std::size_t i = 0; i < ldr.size(); ++i) out.error[i] = std::max(out.error[i], ldr[i]);
    }
    return out;
}

}  // namespace accretion
