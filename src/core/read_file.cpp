#include "accretion/core/read_file.h"

#include <fstream>
#include <iterator>

#include <fmt/format.h>

#include "accretion/core/error.h"

namespace accretion {

std::string readWholeFile(const std::filesystem::path& file, std::string_view what) {
    std::ifstream in(file, std::ios::binary);
    if (!in) throw InputError(fmt::format("{}: cannot open {}", file.string(), what));
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (in.bad()) throw InputError(fmt::format("{}: cannot read {}", file.string(), what));
    return bytes;
}

}  // namespace accretion
