// The report table's CSV and the column numbers plots read it by: a plot
// names its columns by key, so a column added before them cannot shift it
// onto another (as tune's plot once read `seeds` as its bias flag).
#include <catch2/catch.hpp>

#include <sstream>

#include "accretion/io/report_table.h"

using namespace accretion;

TEST_CASE("csvColumn counts the CSV's columns, console-only ones left out", "[io][table]") {
    Table t({{"name", "name", -8}, {"", "console only", 6}, {"ms", "ms", 6, "{:.1f}", "{:.3f}"}, {"flag", "flag", 4}});
    t.add({std::string("a"), std::string("x"), 1.5, true});
    const std::string csv = t.csv();
    std::istringstream lines(csv);
    std::string header, row;
    std::getline(lines, header);
    std::getline(lines, row);
    CHECK(header == "name,ms,flag");
    CHECK(row == "a,1.500,1");
    CHECK(t.csvColumn("name") == 1);
    CHECK(t.csvColumn("ms") == 2);
    CHECK(t.csvColumn("flag") == 3);
    CHECK_THROWS_AS(t.csvColumn("seeds"), std::logic_error);
}
