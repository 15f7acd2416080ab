#pragma once
// A command's results as one table with three printers: console (aligned
// columns), CSV and JSON. cost, converge, bias, compare and the bench suite
// describe their rows once and print them with these.
#include <cstdint>
#include <string>
#include <variant>
#include <vector>

#include <nlohmann/json.hpp>

namespace accretion {

/// A value of a table cell: nothing (JSON null, empty), text, a number or a flag.
using Cell = std::variant<std::monostate, std::string, double, std::int64_t, std::uint64_t, bool>;

/// One column: its key (CSV header, JSON key), how the console shows it
/// (header, width: negative for left-aligned, a fmt spec such as "{:.4f}",
/// the separator before it) and the CSV spec. A column with an empty key is
/// console-only; `console = false` keeps it out of the console.
struct Column {
    std::string key;
    std::string header;         ///< console header
    int width = 0;              ///< console width; < 0: left-aligned
    std::string consoleSpec = "{}";
    std::string csvSpec = "{}";
    bool console = true;
    std::string separator = " ";  ///< console, before the cell (not before the first)
};

class Table {
public:
    explicit Table(std::vector<Column> columns) : columns_(std::move(columns)) {}
    /// A row: one cell per column, in order.
    void add(std::vector<Cell> row) { rows_.push_back(std::move(row)); }

    /// Header line and rows, aligned.
    std::string console() const;
    /// CSV with a header line (columns with a key; a flag is 1 or 0).
    std::string csv() const;
    /// The 1-based column of `key` in csv() (as gnuplot's `using` counts);
    /// throws std::logic_error where no column has that key.
    std::size_t csvColumn(std::string_view key) const;
    /// An array of objects keyed by the column keys (a non-finite number is null).
    nlohmann::json json() const;
    /// "header value" lines of the first row (a one-row report).
    std::string keyValues() const;

private:
    std::string consoleCell(const Column& c, const Cell& v) const;
    std::vector<Column> columns_;
    std::vector<std::vector<Cell>> rows_;
};

}  // namespace accretion
