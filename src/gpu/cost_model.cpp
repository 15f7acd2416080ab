#include "accretion/gpu/cost_model.h"

#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include <Eigen/Dense>
#include <fmt/format.h>

#include "accretion/core/error.h"
#include "accretion/core/parse.h"

namespace accretion {

CostFeatures costFeatures(const PassReport& p) {
    return {double(p.threads), double(p.warpSteps()), double(p.rays), double(p.blasEntries), double(p.anyHits),
            double(p.bytesRead + p.bytesWritten)};
}

CostCoefficients CostCoefficients::defaults() {
    CostCoefficients c;
    c.ns = {0.02, 0.5, 0.5, 0.2, 1.0, 0.002};
    c.source = "defaults (uncalibrated)";
    return c;
}

CostCoefficients CostCoefficients::load(const std::string& path) {
    std::ifstream in(path);
    if (!in) throw InputError(fmt::format("{}: cannot open the cost coefficients", path));
    nlohmann::json j;
    try {
        in >> j;
    } catch (const nlohmann::json::exception& e) {
        throw InputError(fmt::format("{}: not JSON: {}", path, e.what()));
    }
    const nlohmann::json* c = j.contains("coefficients_ns") ? &j["coefficients_ns"] : nullptr;
    if (!c || !c->is_object()) throw InputError(fmt::format("{}: no \"coefficients_ns\" object", path));
    CostCoefficients out;
    out.source = path;
    for (std::size_t k = 0; k < kCostFeatures.size(); ++k) {
        const std::string name(kCostFeatures[k]);
        if (!c->contains(name) || !(*c)[name].is_number())
            throw InputError(fmt::format("{}: coefficients_ns.{} missing or not a number", path, name));
        out.ns[k] = (*c)[name].get<double>();
        if (!std::isfinite(out.ns[k]) || out.ns[k] < 0.0)
            throw InputError(fmt::format("{}: coefficients_ns.{} must be finite and >= 0", path, name));
    }
    return out;
}

nlohmann::json CostCoefficients::toJson() const {
    nlohmann::json c;
    for (std::size_t k = 0; k < kCostFeatures.size(); ++k) c[std::string(kCostFeatures[k])] = ns[k];
    return {{"coefficients_ns", c}, {"source", source}};
}

double CostCoefficients::predictMs(const CostFeatures& f) const {
    double ms = 0.0;
    for (std::size_t k = 0; k < f.size(); ++k) ms += ns[k] * f[k] * 1e-6;
    return ms;
}

std::vector<double> nonNegativeLeastSquares(const std::vector<CostFeatures>& rows, const std::vector<double>& b) {
    const int m = int(rows.size()), n = int(kCostFeatures.size());
    Eigen::MatrixXd A(m, n);
    for (int i = 0; i < m; ++i)
        for (int j = 0; j < n; ++j) A(i, j) = rows[i][j];
    const Eigen::VectorXd y = Eigen::Map<const Eigen::VectorXd>(b.data(), m);
    Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
    std::vector<bool> passive(n, false);
    const double tol = 1e-12 * std::max(1.0, A.norm() * y.norm());
    auto solvePassive = [&]() {
        std::vector<int> idx;
        for (int j = 0; j < n; ++j)
            if (passive[j]) idx.push_back(j);
        Eigen::MatrixXd Ap(m, int(idx.size()));
        for (int k = 0; k < int(idx.size()); ++k) Ap.col(k) = A.col(idx[k]);
        const Eigen::VectorXd zp = Ap.colPivHouseholderQr().solve(y);
        Eigen::VectorXd z = Eigen::VectorXd::Zero(n);
        for (int k = 0; k < int(idx.size()); ++k) z(idx[k]) = zp(k);
        return z;
    };
    for (int outer = 0; outer < 3 * n + 10; ++outer) {
        const Eigen::VectorXd w = A.transpose() * (y - A * x);
        int best = -1;
        for (int j = 0; j < n; ++j)
            if (!passive[j] && w(j) > tol && (best < 0 || w(j) > w(best))) best = j;
        if (best < 0) break;
        passive[best] = true;
        for (int inner = 0; inner < 3 * n + 10; ++inner) {
            const Eigen::VectorXd z = solvePassive();
            bool feasible = true;
            for (int j = 0; j < n; ++j)
                if (passive[j] && z(j) <= 0.0) feasible = false;
            if (feasible) {
                x = z;
                break;
            }
            // Step back towards z until a passive variable hits zero, and free it.
            double alpha = 1.0;
            for (int j = 0; j < n; ++j)
                if (passive[j] && z(j) <= 0.0) alpha = std::min(alpha, x(j) / (x(j) - z(j)));
            x += alpha * (z - x);
            for (int j = 0; j < n; ++j)
                if (passive[j] && x(j) <= 1e-15) {
                    passive[j] = false;
                    x(j) = 0.0;
                }
        }
    }
    return std::vector<double>(x.data(), x.data() + n);
}

namespace {

std::vector<std::string> splitCsv(const std::string& line) {
    std::vector<std::string> out;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) {
        while (!cell.empty() && (cell.back() == '\r' || cell.back() == ' ')) cell.pop_back();
        while (!cell.empty() && cell.front() == ' ') cell.erase(cell.begin());
        out.push_back(cell);
    }
    return out;
}

double parseNumber(const std::string& s, const std::string& where) {
    const std::optional<double> v = accretion::parseNumber(s);
    if (!v || *v < 0.0) throw InputError(fmt::format("{}: '{}' is not a finite non-negative number", where, s));
    return *v;
}

/// Rows of a CSV with a header; each row mapped by column name.
std::vector<std::pair<int, std::map<std::string, std::string>>> readCsv(const std::string& path,
                                                                        const std::vector<std::string>& required) {
    std::ifstream in(path);
    if (!in) throw InputError(fmt::format("{}: cannot open", path));
    std::string line;
    if (!std::getline(in, line)) throw InputError(fmt::format("{}: empty file", path));
    const std::vector<std::string> header = splitCsv(line);
    for (const std::string& r : required)
        if (std::find(header.begin(), header.end(), r) == header.end())
            throw InputError(fmt::format("{}:1: missing column '{}'", path, r));
    std::vector<std::pair<int, std::map<std::string, std::string>>> rows;
    int lineNo = 1;
    while (std::getline(in, line)) {
        ++lineNo;
        if (line.empty() || line == "\r") continue;
        const std::vector<std::string> cells = splitCsv(line);
        if (cells.size() != header.size())
            throw InputError(fmt::format("{}:{}: {} cells, the header has {}", path, lineNo, cells.size(), header.size()));
        std::map<std::string, std::string> row;
        for (std::size_t k = 0; k < header.size(); ++k) row[header[k]] = cells[k];
        rows.emplace_back(lineNo, std::move(row));
    }
    return rows;
}

}  // namespace

std::vector<CostRow> readCounterCsv(const std::string& path) {
    std::vector<std::string> required{"config", "pass"};
    for (std::string_view f : kCostFeatures) required.emplace_back(f);
    std::vector<CostRow> rows;
    for (auto& [lineNo, r] : readCsv(path, required)) {
        CostRow row{r["config"], r["pass"], {}, 0.0};
        for (std::size_t k = 0; k < kCostFeatures.size(); ++k)
            row.features[k] = parseNumber(r[std::string(kCostFeatures[k])],
                                          fmt::format("{}:{}: {}", path, lineNo, kCostFeatures[k]));
        rows.push_back(std::move(row));
    }
    if (rows.empty()) throw InputError(fmt::format("{}: no counter rows", path));
    return rows;
}

void joinTimings(const std::string& path, std::vector<CostRow>& rows) {
    std::map<std::pair<std::string, std::string>, double> ms;
    for (auto& [lineNo, r] : readCsv(path, {"config", "pass", "ms"})) {
        const auto key = std::make_pair(r["config"], r["pass"]);
        if (ms.count(key))
            throw InputError(fmt::format("{}:{}: a second timing for config '{}' pass '{}'", path, lineNo, key.first, key.second));
        ms[key] = parseNumber(r["ms"], fmt::format("{}:{}: ms", path, lineNo));
    }
    std::vector<CostRow> joined;
    for (CostRow& row : rows) {
        auto it = ms.find({row.config, row.pass});
        if (it == ms.end()) continue;  // a pass the user did not time
        row.measuredMs = it->second;
        joined.push_back(row);
        ms.erase(it);
    }
    if (!ms.empty())
        throw InputError(fmt::format("{}: no counters for config '{}' pass '{}'", path, ms.begin()->first.first,
                                     ms.begin()->first.second));
    rows = std::move(joined);
}

Calibration calibrate(const std::vector<CostRow>& rows) {
    if (rows.size() < kCostFeatures.size())
        throw InputError(fmt::format("calibrate: {} timed passes for {} coefficients: time more passes or configurations",
                                     rows.size(), kCostFeatures.size()));
    // Scale each feature column to unit maximum so the fit is well conditioned.
    CostFeatures scale{};
    for (const CostRow& r : rows)
        for (std::size_t k = 0; k < scale.size(); ++k) scale[k] = std::max(scale[k], r.features[k]);
    std::vector<CostFeatures> A;
    std::vector<double> b;
    for (const CostRow& r : rows) {
        CostFeatures f{};
        for (std::size_t k = 0; k < f.size(); ++k) f[k] = scale[k] > 0.0 ? r.features[k] / scale[k] : 0.0;
        A.push_back(f);
        b.push_back(r.measuredMs);
    }
    const std::vector<double> x = nonNegativeLeastSquares(A, b);
    Calibration c;
    c.rows = rows;
    c.coefficients.source = "calibrated";
    for (std::size_t k = 0; k < scale.size(); ++k) c.coefficients.ns[k] = scale[k] > 0.0 ? x[k] / scale[k] * 1e6 : 0.0;
    double mean = 0.0, ssTot = 0.0, ssRes = 0.0;
    for (const CostRow& r : rows) mean += r.measuredMs / double(rows.size());
    for (const CostRow& r : rows) {
        const double p = c.coefficients.predictMs(r.features);
        c.predictedMs.push_back(p);
        ssRes += (p - r.measuredMs) * (p - r.measuredMs);
        ssTot += (r.measuredMs - mean) * (r.measuredMs - mean);
        if (r.measuredMs > 0.0) c.maxRelativeError = std::max(c.maxRelativeError, std::abs(p - r.measuredMs) / r.measuredMs);
    }
    c.rmsMs = std::sqrt(ssRes / double(rows.size()));
    c.r2 = ssTot > 0.0 ? 1.0 - ssRes / ssTot : 1.0;
    return c;
}

nlohmann::json Calibration::toJson() const {
    nlohmann::json j = coefficients.toJson();
    nlohmann::json res = nlohmann::json::array();
    for (std::size_t i = 0; i < rows.size(); ++i)
        res.push_back({{"config", rows[i].config},
                       {"pass", rows[i].pass},
                       {"measured_ms", rows[i].measuredMs},
                       {"predicted_ms", predictedMs[i]},
                       {"residual_ms", predictedMs[i] - rows[i].measuredMs}});
    j["residuals"] = res;
    j["rms_ms"] = rmsMs;
    j["r2"] = r2;
    j["max_relative_error"] = maxRelativeError;
    return j;
}

}  // namespace accretion
