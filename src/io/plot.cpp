#include "accretion/io/plot.h"

#include <cstdio>
#include <stdexcept>

#include <fmt/format.h>

#include "accretion/core/atomic_file.h"

namespace accretion {

std::string gnuplotQuote(const std::string& s) {
    std::string out = "\"";
    for (char c : s) {
        if (c == '\n') {  // a line break inside the string
            out += "\\n";
            continue;
        }
        if (c == '"' || c == '\\') out += '\\';
        out += c;
    }
    return out + "\"";
}

bool plotPng(const std::filesystem::path& png, const std::string& script, int width, int height) {
    bool ok = true;
    std::string why;
    try {
        writeAtomicWith(png, [&](const std::filesystem::path& tmp) {
            FILE* gp = popen("gnuplot 2>&1", "w");
            if (!gp) {
                why = "cannot start gnuplot";
                throw std::runtime_error(why);
            }
            const std::string full = fmt::format("set terminal pngcairo size {},{} noenhanced\nset output {}\n{}\nunset output\n",
                                                 width, height, gnuplotQuote(tmp.string()), script);
            std::fwrite(full.data(), 1, full.size(), gp);
            const int status = pclose(gp);
            if (status != 0 || !std::filesystem::exists(tmp) || std::filesystem::file_size(tmp) == 0) {
                ok = false;
                why = status == 127 * 256 ? "gnuplot not found (Debian package gnuplot-nox)" : "gnuplot failed";
                throw std::runtime_error(why);
            }
        });
    } catch (const std::exception& e) {
        ok = false;
        if (why.empty()) why = e.what();
    }
    if (!ok) fmt::print(stderr, "accretion: {}: no plot: {}\n", png.string(), why);
    return ok;
}

}  // namespace accretion
