#include "accretion/io/report_table.h"

#include <cmath>

#include <fmt/format.h>

#include "accretion/core/csv_cell.h"

namespace accretion {
namespace {

/// A cell written with a fmt spec ("{:.4g}"); nothing as the empty string.
std::string formatCell(const std::string& spec, const Cell& v) {
    return std::visit(
        [&](const auto& x) -> std::string {
            using T = std::decay_t<decltype(x)>;
            if constexpr (std::is_same_v<T, std::monostate>) return "";
            else return fmt::format(fmt::runtime(spec), x);
        },
        v);
}

std::string pad(const std::string& text, int width) {
    if (width < 0) return fmt::format("{:<{}}", text, -width);
    return fmt::format("{:>{}}", text, width);
}

}  // namespace

std::string Table::consoleCell(const Column& c, const Cell& v) const { return pad(formatCell(c.consoleSpec, v), c.width); }

std::string Table::console() const {
    std::string out;
    auto line = [&](auto&& cell) {
        std::string s;
        bool first = true;
        for (std::size_t k = 0; k < columns_.size(); ++k) {
            if (!columns_[k].console) continue;
            s += (first ? "" : columns_[k].separator) + cell(k);
            first = false;
        }
        out += s + "\n";
    };
    line([&](std::size_t k) { return pad(columns_[k].header, columns_[k].width); });
    for (const auto& row : rows_) line([&](std::size_t k) { return consoleCell(columns_[k], row[k]); });
    return out;
}

std::size_t Table::csvColumn(std::string_view key) const {
    std::size_t n = 0;
    for (const Column& c : columns_) {
        if (c.key.empty()) continue;
        ++n;
        if (c.key == key) return n;
    }
    throw std::logic_error("Table::csvColumn: no column " + std::string(key));
}

std::string Table::csv() const {
    std::string out;
    for (const Column& c : columns_)
        if (!c.key.empty()) {
            if (!out.empty()) out += ',';
            out += csvCell(c.key);
        }
    out += "\n";
    for (const auto& row : rows_) {
        std::string line;
        bool first = true;
        for (std::size_t k = 0; k < columns_.size(); ++k) {
            if (columns_[k].key.empty()) continue;
            const Cell& v = row[k];
            if (!first) line += ',';
            line += std::holds_alternative<bool>(v) ? std::string(std::get<bool>(v) ? "1" : "0") : csvCell(formatCell(columns_[k].csvSpec, v));
            first = false;
        }
        out += line + "\n";
    }
    return out;
}

nlohmann::json Table::json() const {
    nlohmann::json out = nlohmann::json::array();
    for (const auto& row : rows_) {
        nlohmann::json j = nlohmann::json::object();
        for (std::size_t k = 0; k < columns_.size(); ++k) {
            if (columns_[k].key.empty()) continue;
            j[columns_[k].key] = std::visit(
                [](const auto& x) -> nlohmann::json {
                    using T = std::decay_t<decltype(x)>;
                    if constexpr (std::is_same_v<T, std::monostate>) return nullptr;
                    else if constexpr (std::is_same_v<T, double>) return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json();
                    else return x;
                },
                row[k]);
        }
        out.push_back(std::move(j));
    }
    return out;
}

std::string Table::keyValues() const {
    std::string out;
    if (rows_.empty()) return out;
    for (std::size_t k = 0; k < columns_.size(); ++k)
        if (columns_[k].console)
            out += fmt::format("{} {}\n", columns_[k].header, formatCell(columns_[k].consoleSpec, rows_[0][k]));
    return out;
}

}  // namespace accretion
