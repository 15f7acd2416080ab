// Progress off a terminal: whole lines, a percentage that only grows, "100%"
// at the end, and "interrupted at N%" (never 100%) when unwound by an exception.
#include <catch2/catch.hpp>

#include <cstdio>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "accretion/core/progress.h"

using namespace accretion;
using Catch::Matchers::Contains;

namespace {

std::string contents(std::FILE* f) {
    std::fflush(f);
    std::rewind(f);
    std::string s;
    char buf[256];
    while (std::size_t n = std::fread(buf, 1, sizeof buf, f)) s.append(buf, n);
    return s;
}

std::vector<std::string> lines(const std::string& s) {
    std::vector<std::string> out;
    std::istringstream in(s);
    for (std::string l; std::getline(in, l);) out.push_back(l);
    return out;
}

}  // namespace

TEST_CASE("progress in a log: whole lines, growing percentages, 100% once at the end", "[core][progress]") {
    std::FILE* f = std::tmpfile();
    REQUIRE(f);
    {
        Progress p("frame 0 estimateLighting", 1000, false, {f, 0.0});
        for (int k = 0; k < 10; ++k) p.advance(100);
    }
    const std::string text = contents(f);
    std::fclose(f);
    CHECK(text.find('\r') == std::string::npos);  // not a terminal: no redraws
    const auto ls = lines(text);
    REQUIRE(ls.size() >= 2);
    double last = -1.0;
    for (std::size_t k = 0; k + 1 < ls.size(); ++k) {
        INFO(ls[k]);
        const auto colon = ls[k].find(": ");
        const double pct = std::stod(ls[k].substr(colon + 2));
        CHECK(pct >= last);
        CHECK(pct <= 100.0);
        CHECK_THAT(ls[k], Contains("eta"));
        last = pct;
    }
    CHECK_THAT(ls.back(), Contains("frame 0 estimateLighting: 100%"));
}

TEST_CASE("progress unwound by an exception says where it stopped, never 100%", "[core][progress]") {
    std::FILE* f = std::tmpfile();
    REQUIRE(f);
    try {
        Progress p("frame 3 estimateLighting", 400, false, {f, 3600.0});
        p.advance(100);
        throw std::runtime_error("SIGINT");
    } catch (const std::runtime_error&) {
    }
    const std::string text = contents(f);
    std::fclose(f);
    CHECK_THAT(text, Contains("frame 3 estimateLighting: interrupted at 25%"));
    CHECK(text.find("100%") == std::string::npos);
}
