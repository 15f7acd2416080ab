#pragma once
#include <filesystem>
#include <string>

namespace accretion {

/// Render a PNG with gnuplot (Debian's gnuplot-nox): `script` is the plot
/// body; the terminal and output lines are added here and the PNG is written
/// to a temporary file and renamed into place. Returns false (and says why
/// on stderr) when gnuplot is missing or fails: a plot never fails a run
/// whose CSV was written.
bool plotPng(const std::filesystem::path& png, const std::string& script, int width = 1000, int height = 600);

/// A string as a gnuplot double-quoted literal.
std::string gnuplotQuote(const std::string& s);

}  // namespace accretion
