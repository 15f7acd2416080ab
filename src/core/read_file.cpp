#include "accretion/core/read_file.h"

#include <iterator>
#include <system_error>

#include <fmt/format.h>

#include "accretion/core/error.h"

namespace accretion {

std::ifstream openInputFile(const std::filesystem::path& file, std::string_view what) {
    std::error_code ec;
    if (std::filesystem::is_directory(file, ec))
        throw InputError(fmt::format("{}: is a directory, not a {}", file.string(), what));
    std::ifstream in(file, std::ios::binary);
    if (!in) throw InputError(fmt::format("{}: cannot open {}", file.string(), what));
    return in;
}

std::string readWholeFile(const std::filesystem::path& file, std::string_view what) {
    std::ifstream in = openInputFile(file, what);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (in.bad()) throw InputError(fmt::format("{}: cannot read {}", file.string(), what));
    return bytes;
}

std::uint64_t bytesLeft(std::ifstream& in) {
    const std::streampos here = in.tellg();
    in.seekg(0, std::ios::end);
    const std::streampos end = in.tellg();
    in.seekg(here);
    return here < 0 || end < here ? 0 : std::uint64_t(end - here);
}

std::string_view withoutBom(std::string_view text) {
    return text.substr(0, 3) == "\xEF\xBB\xBF" ? text.substr(3) : text;
}

}  // namespace accretion
