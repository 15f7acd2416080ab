#include "accretion/gpu/cost_model.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <sstream>

#include <Eigen/Dense>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include "accretion/core/error.h"
#include "accretion/core/read_file.h"
#include "accretion/core/json_text.h"
#include "accretion/core/median.h"
#include "accretion/core/parse.h"
#include "accretion/core/pass.h"

namespace accretion {

namespace {
/// The pass names, for errors that name an unknown one.
std::string knownPasses() { return "passes: " + passNameList(); }
}  // namespace

double coldWork(double rays, double bytes, double workingSetBytes, double cacheBytes) {
    if (!(workingSetBytes > cacheBytes) || !(cacheBytes > 0.0)) return 0.0;
    return (rays > 0.0 ? rays : bytes) * std::log2(workingSetBytes / cacheBytes);
}

CostFeatures costFeatures(const PassReport& p, double cacheBytes) {
    CostFeatures f{};
    for (const CostFeatureInfo& c : kCostFeatureTable) f[c.feature] = c.value(p, cacheBytes);
    return f;
}

CostCoefficients CostCoefficients::defaults() {
    CostCoefficients c;
    c.ns = {0.02, 0.5, 0.5, 0.2, 1.0, 0.002};  // the later counters: not in the uncalibrated guess
    c.source = "defaults (uncalibrated: an order-of-magnitude guess, not a measurement)";
    c.calibrated = false;
    return c;
}

CostCoefficients CostCoefficients::load(const std::string& path) {
    const nlohmann::json j = parseJsonText(readWholeFile(path, "cost coefficients file"), path, "cost coefficients file");
    CostCoefficients out = fromJson(j, path);
    out.source = out.gpu.empty() ? path : fmt::format("{} ({}, measured at {})", path, out.gpu, out.measuredAt);
    return out;
}

CostCoefficients CostCoefficients::committed() {
    CostCoefficients out = fromJson(nlohmann::json::parse(defaultCoefficientsJson()), kDefaultCoefficientsFile);
    out.source = fmt::format("{} calibration of {}, measured at {}", out.gpu, kDefaultCoefficientsFile, out.measuredAt);
    return out;
}

CostCoefficients CostCoefficients::forSetting(const std::string& setting) {
    if (setting.empty()) return committed();
    if (setting == "uncalibrated") return defaults();
    return load(setting);
}

CostCoefficients CostCoefficients::fromJson(const nlohmann::json& j, const std::string& path) {
    if (!j.is_object()) throw InputError(fmt::format("{}: not a coefficients file (a JSON object)", path));
    // What calibrate writes; any other key is a typo that would be ignored.
    static const std::set<std::string> known = {"cache_bytes", "calibrated", "coefficients_ns", "counters", "form", "gpu",
                                                "max_relative_error", "measured_at", "per_pass_ns", "r2", "residuals",
                                                "rms_ms", "source", "timings", "version", "comment"};
    for (const auto& item : j.items())
        if (!known.count(item.key()))
            throw InputError(fmt::format("{}: {}: unknown key ({})", path, item.key(), fmt::join(known, ", ")));
    const nlohmann::json* c = j.contains("coefficients_ns") ? &j["coefficients_ns"] : nullptr;
    if (!c || !c->is_object()) throw InputError(fmt::format("{}: no \"coefficients_ns\" object", path));
    CostCoefficients out;
    out.source = path;
    if (j.contains("gpu") && j["gpu"].is_string()) out.gpu = j["gpu"].get<std::string>();
    if (j.contains("measured_at") && j["measured_at"].is_string()) out.measuredAt = j["measured_at"].get<std::string>();
    // The counters after the first six are optional (files of the first form lack them).
    auto read = [&](const nlohmann::json& obj, const std::string& where, CostFeatures& into) {
        for (const auto& item : obj.items())
            if (std::find(kCostFeatures.begin(), kCostFeatures.end(), item.key()) == kCostFeatures.end())
                throw InputError(fmt::format("{}: {}.{}: not a counter of the cost model (docs/cost-model.md lists them)", path, where, item.key()));
        for (std::size_t k = 0; k < kCostFeatures.size(); ++k) {
            const std::string name(kCostFeatures[k]);
            if (!obj.contains(name) && k >= kBaseCostFeatures) continue;
            if (!obj.contains(name) || !obj[name].is_number())
                throw InputError(fmt::format("{}: {}.{} missing or not a number", path, where, name));
            into[k] = obj[name].get<double>();
            if (!std::isfinite(into[k]) || into[k] < 0.0)
                throw InputError(fmt::format("{}: {}.{} must be finite and >= 0", path, where, name));
        }
    };
    read(*c, "coefficients_ns", out.ns);
    if (j.contains("cache_bytes")) {
        if (!j["cache_bytes"].is_number() || !(j["cache_bytes"].get<double>() > 0.0))
            throw InputError(fmt::format("{}: cache_bytes must be a positive number", path));
        out.cacheBytes = j["cache_bytes"].get<double>();
    }
    if (j.contains("per_pass_ns")) {
        if (!j["per_pass_ns"].is_object()) throw InputError(fmt::format("{}: per_pass_ns is not an object", path));
        for (const auto& [name, obj] : j["per_pass_ns"].items()) {
            if (!obj.is_object()) throw InputError(fmt::format("{}: per_pass_ns.{} is not an object", path, name));
            const std::optional<PassRun> run = parsePassRun(name);
            if (!run || run->run != 1)
                throw InputError(fmt::format("{}: per_pass_ns.{}: not a pass ({})", path, name, knownPasses()));
            read(obj, "per_pass_ns." + name, out.perPass[run->pass]);
        }
    }
    return out;
}

nlohmann::json CostCoefficients::toJson() const {
    nlohmann::json c;
    for (std::size_t k = 0; k < kCostFeatures.size(); ++k) c[std::string(kCostFeatures[k])] = ns[k];
    nlohmann::json j = {{"coefficients_ns", c}, {"cache_bytes", cacheBytes}, {"source", source}, {"calibrated", calibrated}};
    if (!gpu.empty()) j["gpu"] = gpu;
    if (!measuredAt.empty()) j["measured_at"] = measuredAt;
    for (const auto& [pass, f] : perPass)
        for (std::size_t k = 0; k < kCostFeatures.size(); ++k)
            j["per_pass_ns"][std::string(passName(pass))][std::string(kCostFeatures[k])] = f[k];
    return j;
}

namespace {

/// sum coefficient (ns) x counter, in ms.
double dotMs(const CostFeatures& ns, const CostFeatures& f) {
    double ms = 0.0;
    for (std::size_t k = 0; k < f.size(); ++k) ms += ns[k] * f[k] * 1e-6;
    return ms;
}

}  // namespace

double CostCoefficients::predictMs(const CostFeatures& f) const { return dotMs(ns, f); }

double CostCoefficients::predictMs(Pass pass, const CostFeatures& f) const {
    auto it = perPass.find(pass);
    if (it == perPass.end()) it = perPass.find(passInfo(pass).costProxy);
    return dotMs(it == perPass.end() ? ns : it->second, f);
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

/// One CSV line's cells (RFC 4180: a cell in double quotes may hold commas
/// and "" for a quote, as Nsight and spreadsheets export them), trimmed.
std::vector<std::string> splitCsv(const std::string& line, const std::string& where) {
    std::vector<std::string> out(1);
    bool quoted = false, wasQuoted = false;
    for (std::size_t i = 0; i < line.size(); ++i) {
        const char c = line[i];
        if (quoted) {
            if (c != '"') out.back() += c;
            else if (i + 1 < line.size() && line[i + 1] == '"') out.back() += '"', ++i;
            else quoted = false;
        } else if (c == '"' && out.back().find_first_not_of(" ") == std::string::npos) {
            out.back().clear();
            quoted = wasQuoted = true;
        } else if (c == ',') {
            out.emplace_back();
            wasQuoted = false;
        } else if (!(wasQuoted && (c == ' ' || c == '\r'))) {
            out.back() += c;
        }
    }
    if (quoted) throw InputError(fmt::format("{}: a quoted cell is not closed", where));
    for (std::string& cell : out) {
        while (!cell.empty() && (cell.back() == '\r' || cell.back() == ' ')) cell.pop_back();
        while (!cell.empty() && cell.front() == ' ') cell.erase(cell.begin());
    }
    return out;
}

double parseNumber(const std::string& s, const std::string& where) {
    const std::optional<double> v = accretion::parseNumber(s);
    if (!v || *v < 0.0) throw InputError(fmt::format("{}: '{}' is not a finite non-negative number", where, s));
    return *v;
}

/// Rows of a CSV with a header; each row mapped by column name. The header
/// holds every `required` column, and no column but those and `optional`
/// (a misspelt name is an error, not a column of zeros), each once.
std::vector<std::pair<int, std::map<std::string, std::string>>> readCsv(const std::string& path,
                                                                        const std::vector<std::string>& required,
                                                                        const std::vector<std::string>& optional = {}) {
    std::ifstream in = openInputFile(path, "CSV file");
    std::string line;
    if (!std::getline(in, line)) throw InputError(fmt::format("{}: empty file", path));
    const std::vector<std::string> header = splitCsv(std::string(withoutBom(line)), path + ":1");
    if (header.size() == 1 && header[0].find(';') != std::string::npos)
        throw InputError(fmt::format("{}:1: cells separated by ';' (a spreadsheet's export in a decimal-comma locale): expected "
                                     "comma-separated cells with '.' decimals", path));
    for (const std::string& r : required)
        if (std::find(header.begin(), header.end(), r) == header.end())
            throw InputError(fmt::format("{}:1: missing column '{}'", path, r));
    for (std::size_t k = 0; k < header.size(); ++k) {
        const std::string& c = header[k];
        if (std::find(header.begin(), header.begin() + std::ptrdiff_t(k), c) != header.begin() + std::ptrdiff_t(k))
            throw InputError(fmt::format("{}:1: column '{}' twice", path, c));
        if (std::find(required.begin(), required.end(), c) == required.end() &&
            std::find(optional.begin(), optional.end(), c) == optional.end()) {
            std::vector<std::string> known = required;
            known.insert(known.end(), optional.begin(), optional.end());
            throw InputError(fmt::format("{}:1: unknown column '{}' (known: {})", path, c, fmt::join(known, ", ")));
        }
    }
    std::vector<std::pair<int, std::map<std::string, std::string>>> rows;
    int lineNo = 1;
    while (std::getline(in, line)) {
        ++lineNo;
        if (line.empty() || line == "\r") continue;
        const std::vector<std::string> cells = splitCsv(line, fmt::format("{}:{}", path, lineNo));
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
    for (std::size_t k = 0; k < kBaseCostFeatures; ++k) required.emplace_back(kCostFeatures[k]);
    std::vector<std::string> optional{"working_set_bytes", "predicted_ms", "uncalibrated_ms"};
    for (std::size_t k = kBaseCostFeatures; k < kCostFeatures.size(); ++k) optional.emplace_back(kCostFeatures[k]);
    std::vector<CostRow> rows;
    for (auto& [lineNo, r] : readCsv(path, required, optional)) {
        const std::optional<PassRun> pass = parsePassRun(r["pass"]);
        if (!pass) throw InputError(fmt::format("{}:{}: pass '{}' is not a pass ({})", path, lineNo, r["pass"], knownPasses()));
        CostRow row;
        row.config = r["config"];
        row.pass = *pass;
        row.origin = fmt::format("{}:{}", path, lineNo);
        for (std::size_t k = 0; k < kCostFeatures.size(); ++k) {
            const auto cell = r.find(std::string(kCostFeatures[k]));
            if (cell == r.end()) continue;  // a later counter, absent from a CSV of the first form: 0
            row.features[k] = parseNumber(cell->second, fmt::format("{}:{}: {}", path, lineNo, kCostFeatures[k]));
        }
        if (const auto ws = r.find("working_set_bytes"); ws != r.end())
            row.workingSetBytes = parseNumber(ws->second, fmt::format("{}:{}: working_set_bytes", path, lineNo));
        rows.push_back(std::move(row));
    }
    if (rows.empty()) throw InputError(fmt::format("{}: no counter rows", path));
    return rows;
}

void joinTimings(const std::string& path, std::vector<CostRow>& rows) {
    std::map<std::pair<std::string, PassRun>, const CostRow*> counted;
    for (const CostRow& row : rows)
        if (const auto [it, fresh] = counted.emplace(std::make_pair(row.config, row.pass), &row); !fresh)
            throw InputError(fmt::format("{}: a second counter row for config '{}' pass '{}' (the first: {}): a timing joins one row; "
                                         "give each configuration its own `cost --config`", row.origin, row.config, row.pass.label(),
                                         it->second->origin));
    std::map<std::pair<std::string, PassRun>, double> ms;
    // The twin's timing CSVs (accretion-optix --timings) carry what made each row beside it.
    const std::vector<std::string> twinColumns = {"frames", "clusters", "triangles", "rebuilt_clusters", "blas_bytes",
                                                  "blas_memory_bytes", "blas_enqueue_ms", "device", "version", "repeat"};
    for (auto& [lineNo, r] : readCsv(path, {"config", "pass", "ms"}, twinColumns)) {
        const std::optional<PassRun> pass = parsePassRun(r["pass"]);
        if (!pass) throw InputError(fmt::format("{}:{}: pass '{}' is not a pass ({})", path, lineNo, r["pass"], knownPasses()));
        const auto key = std::make_pair(r["config"], *pass);
        if (ms.count(key))
            throw InputError(fmt::format("{}:{}: a second timing for config '{}' pass '{}'", path, lineNo, key.first, r["pass"]));
        ms[key] = parseNumber(r["ms"], fmt::format("{}:{}: ms", path, lineNo));
    }
    // A pass timed once for all its runs: its runs' counters summed into the first run's row.
    std::map<std::pair<std::string, Pass>, std::vector<CostRow*>> runsOf;
    for (CostRow& row : rows) runsOf[{row.config, row.pass.pass}].push_back(&row);
    for (auto& [key, runs] : runsOf) {
        if (runs.size() < 2) continue;
        const auto timed = [&](const CostRow* r) { return ms.count({key.first, r->pass}) > 0; };
        CostRow* first = *std::min_element(runs.begin(), runs.end(), [](const CostRow* a, const CostRow* b) { return a->pass.run < b->pass.run; });
        if (!timed(first) || std::any_of(runs.begin(), runs.end(), [&](const CostRow* r) { return r != first && timed(r); })) continue;
        for (const CostRow* r : runs) {
            if (r == first) continue;
            for (std::size_t k = 0; k < first->features.size(); ++k) first->features[k] += r->features[k];
            first->workingSetBytes = std::max(first->workingSetBytes, r->workingSetBytes);
            first->runs += r->runs;
        }
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
                                     ms.begin()->first.second.label()));
    rows = std::move(joined);
}

namespace {

using FeatureMask = std::array<bool, kCostFeatures.size()>;

FeatureMask firstFeatures(std::size_t n) {
    FeatureMask m{};
    for (std::size_t k = 0; k < n; ++k) m[k] = true;
    return m;
}

/// The counters a pass family is fitted on: buildClusters its builds and
/// dispatches, every other pass all but the builds (isBuildFeature).
FeatureMask passFeatures(Pass pass) {
    const bool build = pass == Pass::buildClusters;
    FeatureMask m{};
    for (std::size_t k = 0; k < m.size(); ++k) m[k] = isBuildFeature(k) == build;
    m[std::size_t(CostFeature::dispatches)] = true;
    return m;
}

/// NNLS of one set of rows over the features of `mask` (the others held at
/// 0); with `relative`, each row weighted by 1 / its measured time.
CostFeatures fitRows(const std::vector<const CostRow*>& rows, const FeatureMask& mask, bool relative) {
    CostFeatures scale{};
    for (const CostRow* r : rows)
        for (std::size_t k = 0; k < mask.size(); ++k)
            if (mask[k]) scale[k] = std::max(scale[k], r->features[k]);
    std::vector<CostFeatures> A;
    std::vector<double> b;
    for (const CostRow* r : rows) {
        const double w = relative && r->measuredMs > 0.0 ? 1.0 / r->measuredMs : 1.0;
        CostFeatures f{};
        for (std::size_t k = 0; k < mask.size(); ++k) f[k] = scale[k] > 0.0 ? w * r->features[k] / scale[k] : 0.0;
        A.push_back(f);
        b.push_back(w * r->measuredMs);
    }
    const std::vector<double> x = nonNegativeLeastSquares(A, b);
    CostFeatures ns{};
    for (std::size_t k = 0; k < mask.size(); ++k) ns[k] = scale[k] > 0.0 ? x[k] / scale[k] * 1e6 : 0.0;
    return ns;
}

/// The configurations of the rows, sorted, each once.
std::vector<std::string> distinctConfigs(const std::vector<const CostRow*>& rows) {
    std::vector<std::string> configs;
    for (const CostRow* r : rows) configs.push_back(r->config);
    std::sort(configs.begin(), configs.end());
    configs.erase(std::unique(configs.begin(), configs.end()), configs.end());
    return configs;
}

/// Root mean square relative error of predicting each configuration's rows
/// from a fit (over `mask`) of the other configurations' rows.
double leaveOneConfigOut(const std::vector<const CostRow*>& rows, const FeatureMask& mask) {
    double sum = 0.0;
    std::size_t n = 0;
    for (const std::string& left : distinctConfigs(rows)) {
        std::vector<const CostRow*> train;
        for (const CostRow* r : rows)
            if (r->config != left) train.push_back(r);
        const CostFeatures ns = fitRows(train, mask, true);
        for (const CostRow* r : rows) {
            if (r->config != left || !(r->measuredMs > 0.0)) continue;
            const double e = (dotMs(ns, r->features) - r->measuredMs) / r->measuredMs;
            sum += e * e;
            ++n;
        }
    }
    return n ? std::sqrt(sum / double(n)) : 0.0;
}

/// A pass timed in fewer configurations than this is fitted as a scale of
/// the fit of every pass (scaledFit): on one to three configurations a fit
/// of its own over every counter is underdetermined, and NNLS then keeps
/// whichever counters these few happen to follow (the world reuse fitted on
/// 100K and 1M priced the cluster's 49-73% high).
constexpr std::size_t kMinConfigsPerPass = 4;

/// `shared` (every pass's fit) times the one factor that fits `rows` best
/// in relative error: sum (s p_i / m_i - 1)^2 is least at s = sum(p_i / m_i)
/// / sum((p_i / m_i)^2).
CostFeatures scaledFit(const std::vector<const CostRow*>& rows, const CostFeatures& shared) {
    double num = 0.0, den = 0.0;
    for (const CostRow* r : rows) {
        if (!(r->measuredMs > 0.0)) continue;
        const double q = dotMs(shared, r->features) / r->measuredMs;
        num += q;
        den += q * q;
    }
    const double s = den > 0.0 ? num / den : 1.0;
    CostFeatures ns = shared;
    for (double& x : ns) x *= s;
    return ns;
}

/// The selected form of one pass: the launch counters (a constant per
/// dispatch, build and refit: always a cost where they occur, and a
/// configuration of their own, such as the only refit, cannot vote for them
/// when left out), then forward selection of the work counters, each step
/// adding the one that lowers the leave-one-configuration-out error most,
/// until none lowers it by more than its standard error; then the fit over
/// the chosen counters. fit() calls it for passes timed in at least
/// kMinConfigsPerPass configurations.
CostFeatures fitSelected(const std::vector<const CostRow*>& rows, const FeatureMask& allowed) {
    const std::size_t nConfigs = distinctConfigs(rows).size();
    FeatureMask chosen{};
    for (std::size_t k = 0; k < kCostFeatureCount; ++k)
        if (kCostFeatureTable[k].launch) chosen[k] = allowed[k];
    double best = leaveOneConfigOut(rows, chosen);
    for (std::size_t step = 0; step < kCostFeatures.size() && step + 2 < nConfigs; ++step) {
        std::size_t pick = kCostFeatures.size();
        double pickError = best;
        for (std::size_t k = 0; k < kCostFeatures.size(); ++k) {
            if (chosen[k] || !allowed[k] || std::none_of(rows.begin(), rows.end(), [&](const CostRow* r) { return r->features[k] > 0.0; }))
                continue;
            FeatureMask m = chosen;
            m[k] = true;
            const double e = leaveOneConfigOut(rows, m);
            if (e < pickError) {
                pickError = e;
                pick = k;
            }
        }
        // One standard error (Breiman's rule; an RMS of n errors has a
        // relative standard error of about 1 / sqrt(2 n)): a counter that
        // gains less may have followed the noise of these configurations.
        if (pick == kCostFeatures.size() || !(pickError < best * (1.0 - 1.0 / std::sqrt(2.0 * double(rows.size()))))) break;
        chosen[pick] = true;
        best = pickError;
    }
    return fitRows(rows, chosen, true);
}

/// The rows with cold_work for a cache of `cacheBytes`.
std::vector<CostRow> withCache(std::vector<CostRow> rows, double cacheBytes) {
    for (CostRow& r : rows) r.features[CostFeature::cold_work] = coldWork(r.features[CostFeature::rays], r.features[CostFeature::bytes], r.workingSetBytes, cacheBytes);
    return rows;
}

std::map<Pass, std::vector<const CostRow*>> rowsByPass(const std::vector<CostRow>& rows) {
    std::map<Pass, std::vector<const CostRow*>> byPass;
    for (const CostRow& r : rows) byPass[r.pass.pass].push_back(&r);
    return byPass;
}

/// The cache of cold_work: of 128 KiB, 256 KiB ... 64 MiB, the one whose
/// per-pass fits predict left-out configurations best (the sum over passes
/// of the leave-one-configuration-out error). Rows without a working set
/// keep the default.
double chooseCache(const std::vector<CostRow>& rows) {
    if (std::none_of(rows.begin(), rows.end(), [](const CostRow& r) { return r.workingSetBytes > 0.0; })) return kDefaultCacheBytes;
    double best = kDefaultCacheBytes, bestError = std::numeric_limits<double>::infinity();
    for (int k = -3; k <= 6; ++k) {
        const double cache = std::ldexp(1024.0 * 1024.0, k);
        const std::vector<CostRow> trial = withCache(rows, cache);
        double error = 0.0;
        for (const auto& [pass, rs] : rowsByPass(trial)) error += leaveOneConfigOut(rs, passFeatures(pass));
        if (error < bestError) {
            bestError = error;
            best = cache;
        }
    }
    return best;
}

/// The coefficients of a form; per_pass and selected choose their cache
/// first (chooseCache), and fit the rows' cold_work for it.
CostCoefficients fit(const std::vector<CostRow>& input, CostModelForm form) {
    CostCoefficients c;
    if (form == CostModelForm::shared) {
        std::vector<const CostRow*> all;
        for (const CostRow& r : input) all.push_back(&r);
        c.ns = fitRows(all, firstFeatures(kBaseCostFeatures), false);
        c.source = "calibrated (shared)";
        return c;
    }
    c.cacheBytes = chooseCache(input);
    const std::vector<CostRow> rows = withCache(input, c.cacheBytes);
    std::vector<const CostRow*> all;
    for (const CostRow& r : rows) all.push_back(&r);
    c.ns = fitRows(all, firstFeatures(kCostFeatures.size()), true);  // for a pass no row has
    for (const auto& [pass, rs] : rowsByPass(rows))
        c.perPass[pass] = distinctConfigs(rs).size() < kMinConfigsPerPass ? scaledFit(rs, c.ns)
                          : form == CostModelForm::selected           ? fitSelected(rs, passFeatures(pass))
                                                                      : fitRows(rs, passFeatures(pass), true);
    c.source = fmt::format("calibrated ({})", costModelFormName(form));
    return c;
}

}  // namespace

Calibration calibrate(const std::vector<CostRow>& rows, CostModelForm form) {
    const std::size_t unknowns = form == CostModelForm::shared ? kBaseCostFeatures : kCostFeatures.size();
    if (rows.size() < unknowns)
        throw InputError(fmt::format("calibrate: {} timed passes for {} coefficients: time more passes or configurations",
                                     rows.size(), unknowns));
    Calibration c;
    c.coefficients = fit(rows, form);
    c.rows = withCache(rows, c.coefficients.cacheBytes);
    double mean = 0.0, ssTot = 0.0, ssRes = 0.0;
    for (const CostRow& r : c.rows) mean += r.measuredMs / double(rows.size());
    for (const CostRow& r : c.rows) {
        const double p = c.coefficients.predictMs(r.pass.pass, r.features);
        c.predictedMs.push_back(p);
        ssRes += (p - r.measuredMs) * (p - r.measuredMs);
        ssTot += (r.measuredMs - mean) * (r.measuredMs - mean);
        if (r.measuredMs > 0.0) c.maxRelativeError = std::max(c.maxRelativeError, std::abs(p - r.measuredMs) / r.measuredMs);
    }
    c.rmsMs = std::sqrt(ssRes / double(rows.size()));
    c.r2 = ssTot > 0.0 ? 1.0 - ssRes / ssTot : 1.0;
    return c;
}

namespace {
/// The spatial reuse passes (restir's screen disc, particle_restir's world
/// neighbours): the iterated ones of the held-out check.
bool isSpatialReuse(Pass p) { return p == Pass::spatialResampling || p == Pass::resampleWorldNeighbours; }
}  // namespace

Holdout holdout(const std::vector<CostRow>& rows, CostModelForm form, double fraction, std::uint64_t seed) {
    std::vector<std::string> configs;
    for (const CostRow& r : rows)
        if (std::find(configs.begin(), configs.end(), r.config) == configs.end()) configs.push_back(r.config);
    std::sort(configs.begin(), configs.end());
    if (configs.size() < 2) throw InputError("calibrate --holdout: at least 2 configurations are needed");
    std::mt19937_64 rng(seed);  // its numbers are fixed by the standard; the shuffle is ours
    for (std::size_t i = configs.size() - 1; i > 0; --i) std::swap(configs[i], configs[rng() % (i + 1)]);
    const std::size_t nFit =
        std::clamp<std::size_t>(static_cast<std::size_t>(std::lround(fraction * double(configs.size()))), 1, configs.size() - 1);
    Holdout h;
    h.form = form;
    h.fitted.assign(configs.begin(), configs.begin() + std::ptrdiff_t(nFit));
    h.predicted.assign(configs.begin() + std::ptrdiff_t(nFit), configs.end());
    std::sort(h.fitted.begin(), h.fitted.end());
    std::sort(h.predicted.begin(), h.predicted.end());
    auto in = [](const std::vector<std::string>& v, const std::string& x) { return std::binary_search(v.begin(), v.end(), x); };
    std::vector<CostRow> train;
    for (const CostRow& r : rows)
        if (in(h.fitted, r.config)) train.push_back(r);
    const CostCoefficients c = fit(train, form);
    const std::vector<CostRow> priced = withCache(rows, c.cacheBytes);
    using Errors = std::vector<std::pair<double, std::string>>;  // relative error, configuration
    std::map<Pass, Errors> byPass;
    Errors all;
    struct Sum {
        double predicted = 0.0, measured = 0.0;
        std::uint32_t runs = 0;
    };
    std::map<std::string, Sum> frame, spatial;  // by configuration
    for (const CostRow& r : priced) {
        if (!in(h.predicted, r.config) || !(r.measuredMs > 0.0)) continue;
        const double predicted = c.predictMs(r.pass.pass, r.features);
        h.rows.push_back(r);
        h.predictedMs.push_back(predicted);
        const double e = std::abs(predicted - r.measuredMs) / r.measuredMs;
        byPass[r.pass.pass].push_back({e, r.config});
        all.push_back({e, r.config});
        for (Sum* s : {&frame[r.config], isSpatialReuse(r.pass.pass) ? &spatial[r.config] : nullptr})
            if (s) {
                s->predicted += predicted;
                s->measured += r.measuredMs;
                s->runs += r.runs;
            }
    }
    auto summary = [](std::optional<Pass> pass, const Errors& es) {
        HoldoutError he{pass, es.size(), 0.0, 0.0, ""};
        std::vector<double> v;
        for (const auto& [e, config] : es) {
            v.push_back(e);
            if (e >= he.worst) {
                he.worst = e;
                he.worstConfig = config;
            }
        }
        he.median = median(v);
        return he;
    };
    for (const auto& [pass, es] : byPass) h.passes.push_back(summary(pass, es));
    if (!all.empty()) h.passes.push_back(summary(std::nullopt, all));
    Errors frames, iterated;
    for (const auto& [config, s] : frame) frames.push_back({std::abs(s.predicted - s.measured) / s.measured, config});
    for (const auto& [config, s] : spatial)
        if (s.runs >= 2) iterated.push_back({std::abs(s.predicted - s.measured) / s.measured, config});
    h.frames = summary(std::nullopt, frames);
    h.iteratedSpatial = summary(Pass::spatialResampling, iterated);
    return h;
}

nlohmann::json Holdout::toJson() const {
    nlohmann::json p = nlohmann::json::array();
    for (const HoldoutError& e : passes)
        p.push_back({{"pass", e.label()}, {"rows", e.rows}, {"median_relative_error", e.median},
                     {"worst_relative_error", e.worst}, {"worst_config", e.worstConfig}});
    nlohmann::json rs = nlohmann::json::array();
    for (std::size_t i = 0; i < rows.size(); ++i)
        rs.push_back({{"config", rows[i].config}, {"pass", rows[i].pass.label()}, {"measured_ms", rows[i].measuredMs},
                      {"predicted_ms", predictedMs[i]}});
    const auto summary = [](const HoldoutError& e) {
        return nlohmann::json{{"configurations", e.rows}, {"median_relative_error", e.median}, {"worst_relative_error", e.worst},
                              {"worst_config", e.worstConfig}};
    };
    return {{"form", costModelFormName(form)}, {"fitted", fitted}, {"predicted", predicted}, {"passes", p},
            {"frames", summary(frames)}, {"iterated_spatial", summary(iteratedSpatial)}, {"rows", rs}};
}

nlohmann::json Calibration::toJson() const {
    nlohmann::json j = coefficients.toJson();
    nlohmann::json res = nlohmann::json::array();
    for (std::size_t i = 0; i < rows.size(); ++i)
        res.push_back({{"config", rows[i].config},
                       {"pass", rows[i].pass.label()},
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
